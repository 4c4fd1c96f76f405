// The property keys of the entities of type $type of log $log, read from all of them, and which
// of them hold zoned times (the keys of events are known from the log's event table). robotale
// writes one type per property, so a key's first value tells it.
MATCH (n:Entity)
WHERE n.log = $log AND n.type = $type AND n.id IS NOT NULL
UNWIND keys(n) AS key
WITH key, collect(n[key] IS :: ZONED DATETIME)[0] AS time
RETURN collect(key) AS keys, [k IN collect(CASE WHEN time THEN key END) WHERE k IS NOT NULL] AS times
