// The element ids of the events of log $log with the ids $ids[i], found by the key every event
// has (the log and its id): the members of an aggregation step and the other ends of its lifted
// edges, which robotale computes from the log's event table. Returns [row, element id] pairs.
UNWIND range(0, size($ids) - 1) AS i
MATCH (n:Event {log: $log, id: $ids[i]})
RETURN collect([i, elementId(n)]) AS nodes
