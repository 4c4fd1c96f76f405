// One batch of classes of type $type (the key $key, e.g. ["activity", "robot"]) for log $log,
// given as columns: $ids and $properties {key property: [values]}. A class the log already
// has is found rather than created again (its key values are the same). Returns
// [row, element id] pairs.
UNWIND range(0, size($ids) - 1) AS i
MERGE (c:Class {log: $log, type: $type, id: $ids[i]})
ON CREATE SET c.key = $key
FOREACH (k IN keys($properties) | SET c[k] = $properties[k][i])
RETURN collect([i, elementId(c)]) AS nodes
