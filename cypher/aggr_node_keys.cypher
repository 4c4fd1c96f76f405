// The property keys of the nodes a step may aggregate, and which of them hold zoned times:
// the events of log $log ($type null) or its entities of type $type, the first $limit of
// them (the events' keys are also on the Log node; an entity type's keys are read from all
// its entities), but for `_aggregate`, the mark of an aggregation step. robotale writes one
// type per property, so a key's first value tells it.
MATCH (n)
WHERE (($type IS NULL AND n:Event) OR ($type IS NOT NULL AND n:Entity AND n.type = $type))
  AND n.log = $log AND n.id IS NOT NULL
WITH n LIMIT $limit
UNWIND [k IN keys(n) WHERE k <> '_aggregate'] AS key
WITH key, collect(n[key] IS :: ZONED DATETIME)[0] AS time
RETURN collect(key) AS keys, [k IN collect(CASE WHEN time THEN key END) WHERE k IS NOT NULL] AS times
