// One batch of objects of type $type of log $log with their attributes, given as columns:
// $ids and $properties {name: [values]} (a null value is not stored). An object no event
// relates to gets its Entity node here.
UNWIND range(0, size($ids) - 1) AS i
MERGE (n:Entity {log: $log, type: $type, id: $ids[i]})
FOREACH (key IN keys($properties) | SET n[key] = $properties[key][i])
