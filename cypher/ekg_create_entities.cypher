// One batch of entities of type $type for log $log; returns [row, node id] pairs so the
// edges written next can find the nodes directly. An entity the log already has (a run
// appended to it names the same robot) is found rather than created again.
UNWIND range(0, size($ids) - 1) AS i
MERGE (n:Entity {log: $log, type: $type, id: $ids[i]})
RETURN collect([i, id(n)]) AS nodes
