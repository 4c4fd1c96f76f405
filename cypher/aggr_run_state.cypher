// What a run of an aggregation specification on log $log reads of its Log node, run in the
// transaction that takes the log's write lock (no row when there is no such log): its entity
// types and event properties, and how many entities it has, aggregated or not (with the members
// of its aggregation steps, OCEAN's verification counts; the events are counted in the log's
// event table).
MATCH (l:Log {name: $log})
RETURN l.entityTypes AS entityTypes, l.properties AS properties,
       COUNT {
         MATCH (n:Entity)
         WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL
       } AS entities
