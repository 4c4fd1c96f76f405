// The element ids of the entities of type $type of log $log, by id, as columns (one row), as
// aggr_event_element_ids for events.
MATCH (n:Entity)
WHERE n.log = $log AND n.type = $type AND n.id IS NOT NULL
RETURN collect(n.id) AS ids, collect(elementId(n)) AS elements
