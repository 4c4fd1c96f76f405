// Undo the marks earlier versions of robotale left on the members of aggregation steps $step,
// $step + 1 ... of log $log: the aggregate's id "<step>:<name>" in the property `_aggregate`
// of each event and entity it held (robotale's own property names start with a letter, so no
// log has a column of that name). Batched: run it as an auto-commit query.
MATCH (n:Event)
WHERE n.log = $log AND n.id IS NOT NULL AND n._aggregate IS NOT NULL
  AND toInteger(split(n._aggregate, ':')[0]) >= $step
CALL (n) { REMOVE n._aggregate } IN TRANSACTIONS OF 10000 ROWS;
MATCH (n:Entity)
WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL AND n._aggregate IS NOT NULL
  AND toInteger(split(n._aggregate, ':')[0]) >= $step
CALL (n) { REMOVE n._aggregate } IN TRANSACTIONS OF 10000 ROWS;
