// The entities of type $type of log $log that pass the step's filter (robotale leaves out those
// an earlier step collapsed), as columns (one row: less to send than a row per entity): their
// ids and the properties $properties (those in $times, zoned times, as Unix
// nanoseconds). `true /*WHERE*/` is where robotale puts the step's checked `where`
// (robotale.ekg.where: validated property names and parameters only).
MATCH (n:Entity)
WHERE n.log = $log AND n.type = $type AND n.id IS NOT NULL
  AND (true /*WHERE*/)
WITH n,
     [k IN $properties |
       CASE WHEN k IN $times THEN n[k].epochSeconds * 1000000000 + n[k].nanosecond
            ELSE n[k] END] AS values
RETURN collect(n.id) AS ids, collect(values) AS values
