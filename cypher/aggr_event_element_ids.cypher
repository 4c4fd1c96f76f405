// The element ids of the events of log $log, by id, as columns (one row): read once per
// aggregation run, so its lifted edges find their ends by element id rather than each
// looking an event up by key (read from the key's index, no event is visited for its id).
MATCH (e:Event)
WHERE e.log = $log AND e.id IS NOT NULL
RETURN collect(e.id) AS ids, collect(elementId(e)) AS elements
