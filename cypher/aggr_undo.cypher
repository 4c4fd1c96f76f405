// Undo the aggregation steps $step, $step + 1 ... of log $log: their aggregates go with
// every edge they have (memberships and lifted edges; each lifted edge touches an
// aggregate of its own step), then the records of the steps. Batched: run it as an
// auto-commit query (in Neo4j Browser: prefix :auto).
MATCH (a:Aggregate)
WHERE a.log = $log AND a.step >= $step AND a.id IS NOT NULL
CALL (a) { DETACH DELETE a } IN TRANSACTIONS OF 100 ROWS;
MATCH (s:AggregationStep)
WHERE s.log = $log AND s.step >= $step
DELETE s;
