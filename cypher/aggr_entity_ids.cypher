// The element ids of the entities of log $log of type $types[i] and id $ids[i], found by the key
// every entity has (the log, its type and id). Returns [row, element id] pairs.
UNWIND range(0, size($ids) - 1) AS i
MATCH (n:Entity {log: $log, type: $types[i], id: $ids[i]})
RETURN collect([i, elementId(n)]) AS nodes
