// The property keys of the nodes a step may aggregate: the events of log $log ($type null)
// or its entities of type $type, and which of them hold zoned times. A sample of each
// key's values tells its type: robotale writes one type per property.
MATCH (n)
WHERE (($type IS NULL AND n:Event) OR ($type IS NOT NULL AND n:Entity AND n.type = $type))
  AND n.log = $log AND n.id IS NOT NULL
WITH n LIMIT 10000
UNWIND keys(n) AS key
WITH key, collect(n[key] IS :: ZONED DATETIME)[0] AS time
RETURN collect(key) AS keys, [k IN collect(CASE WHEN time THEN key END) WHERE k IS NOT NULL] AS times
