// The property keys of the entities of each type in $types of log $log, read from all of them,
// and which of them hold zoned times (the keys of events are known from the log's event table):
// one row per type that has entities, all the specification's types in one round trip.
// robotale writes one type per property, so a key's first value tells it: the values are
// read from one entity per distinct set of keys, not from every entity (reading each
// entity's every value cost most of the query).
MATCH (n:Entity)
WHERE n.log = $log AND n.type IN $types AND n.id IS NOT NULL
WITH n.type AS type, keys(n) AS keys, head(collect(n)) AS sample
UNWIND keys AS key
WITH type, key, collect(sample[key] IS :: ZONED DATETIME)[0] AS time
RETURN type, collect(key) AS keys,
       [k IN collect(CASE WHEN time THEN key END) WHERE k IS NOT NULL] AS times
