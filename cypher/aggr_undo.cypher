// Undo the aggregation steps $step, $step + 1 ... of log $log: the edges of their aggregates
// first (memberships and lifted edges; each lifted edge touches an aggregate of its own
// step), in batches, since one aggregate may hold a million nodes; then the aggregates and
// the records of the steps. Batched: run it as an auto-commit query (in Neo4j Browser:
// prefix :auto).
MATCH (a:Aggregate)
WHERE a.log = $log AND a.step >= $step AND a.id IS NOT NULL
MATCH (a)-[r]-()
CALL (r) { DELETE r } IN TRANSACTIONS OF 10000 ROWS;
MATCH (a:Aggregate)
WHERE a.log = $log AND a.step >= $step AND a.id IS NOT NULL
CALL (a) { DETACH DELETE a } IN TRANSACTIONS OF 1000 ROWS;
MATCH (s:AggregationStep)
WHERE s.log = $log AND s.step >= $step
DELETE s;
