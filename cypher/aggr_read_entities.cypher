// The entities of type $type of log $log that no aggregate holds yet and that pass the
// step's filter, each with its node id and the properties $properties (those in $times,
// zoned times, as Unix milliseconds). `true /*WHERE*/` is where robotale puts the step's
// checked `where` (robotale.ekg.where: validated property names and parameters only).
MATCH (n:Entity)
WHERE n.log = $log AND n.type = $type AND n.id IS NOT NULL AND NOT (n)-[:AGGREGATED_IN]->()
  AND (true /*WHERE*/)
RETURN id(n) AS node,
       [k IN $properties | CASE WHEN k IN $times THEN n[k].epochMillis ELSE n[k] END] AS values
