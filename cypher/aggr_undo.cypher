// Undo the aggregation steps $step, $step + 1 ... of log $log: the lifted edges of their
// aggregates first (each touches an aggregate of its own step), in batches, since one step
// may lift millions; then the lists of the nodes they hold (AggregateMembers), the aggregates
// and the records of the steps. Batched: run it as an
// auto-commit query (in Neo4j Browser: prefix :auto).
MATCH (a:Aggregate)
WHERE a.log = $log AND a.step >= $step AND a.id IS NOT NULL
MATCH (a)-[r]-()
CALL (r) { DELETE r } IN TRANSACTIONS OF 10000 ROWS;
MATCH (m:AggregateMembers)
WHERE m.log = $log AND m.step >= $step
CALL (m) { DELETE m } IN TRANSACTIONS OF 100 ROWS;
MATCH (a:Aggregate)
WHERE a.log = $log AND a.step >= $step AND a.id IS NOT NULL
CALL (a) { DETACH DELETE a } IN TRANSACTIONS OF 1000 ROWS;
MATCH (s:AggregationStep)
WHERE s.log = $log AND s.step >= $step
DELETE s;
