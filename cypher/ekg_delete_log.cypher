// Delete one event log: its events, entities (and their objects' attribute changes), classes
// and aggregates with all their relationships, then its Log node. Batched: run it as an auto-commit query (in Neo4j Browser: prefix :auto).
// The `IS NOT NULL` tests let the (log, ...) key indexes find the nodes.
MATCH (e:Event) WHERE e.log = $log AND e.id IS NOT NULL
CALL (e) { DETACH DELETE e } IN TRANSACTIONS OF 10000 ROWS;
MATCH (c:AttributeChange) WHERE c.log = $log
CALL (c) { DETACH DELETE c } IN TRANSACTIONS OF 10000 ROWS;
MATCH (n:Entity) WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL
CALL (n) { DETACH DELETE n } IN TRANSACTIONS OF 10000 ROWS;
MATCH (c:Class) WHERE c.log = $log AND c.type IS NOT NULL AND c.id IS NOT NULL
CALL (c) { DETACH DELETE c } IN TRANSACTIONS OF 10000 ROWS;
MATCH (a:Aggregate) WHERE a.log = $log AND a.step IS NOT NULL AND a.id IS NOT NULL
CALL (a) { DETACH DELETE a } IN TRANSACTIONS OF 1000 ROWS;
MATCH (m:AggregateMembers) WHERE m.log = $log
CALL (m) { DELETE m } IN TRANSACTIONS OF 100 ROWS;
MATCH (s:AggregationStep) WHERE s.log = $log AND s.step IS NOT NULL
DELETE s;
MATCH (l:Log {name: $log})
DETACH DELETE l;
