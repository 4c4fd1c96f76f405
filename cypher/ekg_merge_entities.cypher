// One batch of entities of type $type for the stored log $log, to which runs are appended;
// returns [row, element id] pairs. An entity the log already has (the appended runs name the
// same robot) is found rather than created again.
UNWIND range(0, size($ids) - 1) AS i
MERGE (n:Entity {log: $log, type: $type, id: $ids[i]})
RETURN collect([i, elementId(n)]) AS nodes
