// The property keys of the entities of each type in $types of log $log, read from all of them,
// and which of them hold zoned times (the keys of events are known from the log's event table):
// one row per type that has entities, all the specification's types in one round trip.
// robotale writes one type per property, so a key's first value tells it.
MATCH (n:Entity)
WHERE n.log = $log AND n.type IN $types AND n.id IS NOT NULL
UNWIND keys(n) AS key
WITH n.type AS type, key, collect(n[key] IS :: ZONED DATETIME)[0] AS time
RETURN type, collect(key) AS keys,
       [k IN collect(CASE WHEN time THEN key END) WHERE k IS NOT NULL] AS times
