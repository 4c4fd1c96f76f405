// Give the events of a live log (element ids $nodes[i]) their id $ids[i] and position $orders[i]
// in the log as it stands now: an event heard late (an in-progress sample placed between a
// start and its completion) moves the events after it.
UNWIND range(0, size($nodes) - 1) AS i
MATCH (e:Event) WHERE elementId(e) = $nodes[i] AND e.log = $log
SET e.id = $ids[i], e.order = $orders[i]
