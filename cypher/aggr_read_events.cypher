// The events of log $log that no aggregate holds yet (no `_aggregate`) and that pass the
// step's filter, as columns (one row: less to send than a row per event): their node ids,
// the properties $properties (those in $times, zoned times, as Unix nanoseconds) and, for
// each entity type in $entityTypes, what each event is correlated to there: the id of the
// aggregate that holds the entity (its `_aggregate`), else the entity's id.
// `true /*WHERE*/` is where robotale puts the step's checked `where` (robotale.ekg.where:
// validated property names and parameters only).
MATCH (n:Event)
WHERE n.log = $log AND n.id IS NOT NULL AND n._aggregate IS NULL
  AND (true /*WHERE*/)
WITH n,
     [k IN $properties |
       CASE WHEN k IN $times THEN n[k].epochSeconds * 1000000000 + n[k].nanosecond
            ELSE n[k] END] AS values,
     [t IN $entityTypes |
       [(n)-[:CORR]->(x:Entity {type: t}) |
         coalesce(x._aggregate, x.id)]] AS entities
RETURN collect(elementId(n)) AS nodes, collect(values) AS values, collect(entities) AS entities
