// One batch of events of log $log with the edges that start at them, given as columns: $ids,
// $orders (position in the log), the time as Unix $seconds + $nanos shown in the zone
// $timezone, $properties {key: [values]} for every other property (null values are not
// stored), $entities, the element ids of each event's entities (CORR), $classes, the element ids
// of each event's classes, one per aggregation key (OBSERVED), and the DF and COMM edges
// between two events of this batch, by position in it: $df {sources, targets, entityTypes,
// entityIds}, $comm {sources, targets, msgIds}. An edge created in the transaction that
// creates both its ends needs no lookup and no lock of a stored node. Returns
// [position, element id] pairs.
UNWIND range(0, size($ids) - 1) AS i
CREATE (e:Event {log: $log, id: $ids[i], order: $orders[i],
                 timestamp: datetime({epochSeconds: $seconds[i], nanosecond: $nanos[i],
                                      timezone: $timezone})})
FOREACH (key IN keys($properties) | SET e[key] = $properties[key][i])
WITH e, i
CALL (e, i) {
  UNWIND $entities[i] AS entity
  MATCH (n) WHERE elementId(n) = entity
  CREATE (e)-[:CORR]->(n)
}
CALL (e, i) {
  UNWIND $classes[i] AS class
  MATCH (c) WHERE elementId(c) = class
  CREATE (e)-[:OBSERVED]->(c)
}
WITH e ORDER BY i
WITH collect(e) AS events
CALL (events) {
  UNWIND range(0, size($df.sources) - 1) AS j
  WITH events[$df.sources[j]] AS a, events[$df.targets[j]] AS b, j
  CREATE (a)-[:DF {entityType: $df.entityTypes[j], entityId: $df.entityIds[j]}]->(b)
}
CALL (events) {
  UNWIND range(0, size($comm.sources) - 1) AS j
  WITH events[$comm.sources[j]] AS a, events[$comm.targets[j]] AS b, j
  CREATE (a)-[:COMM {msgId: $comm.msgIds[j]}]->(b)
}
RETURN [k IN range(0, size(events) - 1) | [k, elementId(events[k])]] AS nodes
