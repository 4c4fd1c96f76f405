// Constraints and indexes of the event knowledge graph (idempotent). Several logs share one
// database, so every key starts with the log's name.
CREATE CONSTRAINT ekg_event_key IF NOT EXISTS
FOR (e:Event) REQUIRE (e.log, e.id) IS UNIQUE;
CREATE CONSTRAINT ekg_entity_key IF NOT EXISTS
FOR (n:Entity) REQUIRE (n.log, n.type, n.id) IS UNIQUE;
CREATE CONSTRAINT ekg_class_key IF NOT EXISTS
FOR (c:Class) REQUIRE (c.log, c.type, c.id) IS UNIQUE;
CREATE CONSTRAINT ekg_log_name IF NOT EXISTS
FOR (l:Log) REQUIRE l.name IS UNIQUE;
CREATE CONSTRAINT ekg_log_lock IF NOT EXISTS
FOR (k:LogLock) REQUIRE k.name IS UNIQUE;
CREATE CONSTRAINT ekg_aggregate_key IF NOT EXISTS
FOR (a:Aggregate) REQUIRE (a.log, a.step, a.id) IS UNIQUE;
CREATE CONSTRAINT ekg_aggregation_step_key IF NOT EXISTS
FOR (s:AggregationStep) REQUIRE (s.log, s.step) IS UNIQUE;
CREATE INDEX ekg_attribute_change_log IF NOT EXISTS
FOR (c:AttributeChange) ON (c.log);;
// a live run's tags and odometry samples, read by a following page as they grow: the new ones
// after a number, and the highest number (how many there are) without counting them all
CREATE INDEX live_tag_seq IF NOT EXISTS
FOR (t:LiveTag) ON (t.log, t.seq);
CREATE INDEX live_pose_seq IF NOT EXISTS
FOR (p:LivePose) ON (p.log, p.seq)
