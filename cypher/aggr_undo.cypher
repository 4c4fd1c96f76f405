// Undo the aggregation steps $step, $step + 1 ... of log $log: the lifted edges of their
// aggregates first (each touches an aggregate of its own step), in batches, since one step
// may lift millions; then the marks of the nodes they hold (`_aggregate`, the aggregate's id
// "<step>:<name>"), the aggregates and the records of the steps. Batched: run it as an
// auto-commit query (in Neo4j Browser: prefix :auto).
MATCH (a:Aggregate)
WHERE a.log = $log AND a.step >= $step AND a.id IS NOT NULL
MATCH (a)-[r]-()
CALL (r) { DELETE r } IN TRANSACTIONS OF 10000 ROWS;
MATCH (n:Event)
WHERE n.log = $log AND n.id IS NOT NULL AND n._aggregate IS NOT NULL
  AND toInteger(split(n._aggregate, ':')[0]) >= $step
CALL (n) { REMOVE n._aggregate } IN TRANSACTIONS OF 10000 ROWS;
MATCH (n:Entity)
WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL AND n._aggregate IS NOT NULL
  AND toInteger(split(n._aggregate, ':')[0]) >= $step
CALL (n) { REMOVE n._aggregate } IN TRANSACTIONS OF 10000 ROWS;
MATCH (a:Aggregate)
WHERE a.log = $log AND a.step >= $step AND a.id IS NOT NULL
CALL (a) { DETACH DELETE a } IN TRANSACTIONS OF 1000 ROWS;
MATCH (s:AggregationStep)
WHERE s.log = $log AND s.step >= $step
DELETE s;
