// One batch of entities of type $type for log $log, which has none yet (appends use
// ekg_merge_entities); returns [row, element id] pairs so the edges written next can find the
// nodes directly.
UNWIND range(0, size($ids) - 1) AS i
CREATE (n:Entity {log: $log, type: $type, id: $ids[i]})
RETURN collect([i, elementId(n)]) AS nodes
