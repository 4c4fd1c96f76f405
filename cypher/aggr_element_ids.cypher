// The element ids of the events $events (ids) and of the entities $entities (ids, of the types
// $types at the same positions) of log $log that an aggregation run's lifted edges reach, each
// found by its key's index; returned as columns (one row): the positions found in each list,
// and the element ids at those positions. Read once per run, so the lifted edges find their
// ends by element id rather than each looking its end up by key as it is written; only these
// ends, not every event and entity of the log (most lifted edges join two aggregates).
CALL () {
  UNWIND range(0, size($events) - 1) AS i
  WITH i, $events[i] AS id
  MATCH (e:Event {log: $log, id: id})
  RETURN collect(i) AS eventsFound, collect(elementId(e)) AS eventElements
}
CALL () {
  UNWIND range(0, size($entities) - 1) AS i
  WITH i, $types[i] AS type, $entities[i] AS id
  MATCH (n:Entity {log: $log, type: type, id: id})
  RETURN collect(i) AS entitiesFound, collect(elementId(n)) AS entityElements
}
RETURN eventsFound, eventElements, entitiesFound, entityElements
