// One batch of events of log $log with their CORR and OBSERVED edges, given as columns: $ids,
// $orders (position in the log), the time as Unix $seconds + $nanos shown in the zone
// $timezone, $properties {key: [values]} for every other property (null values are not
// stored), $entities, the node ids of each event's entities, and $classes, the node ids of
// each event's classes (one per aggregation key). Returns [row, node id] pairs.
UNWIND range(0, size($ids) - 1) AS i
CREATE (e:Event {log: $log, id: $ids[i], order: $orders[i],
                 timestamp: datetime({epochSeconds: $seconds[i], nanosecond: $nanos[i],
                                      timezone: $timezone})})
FOREACH (key IN keys($properties) | SET e[key] = $properties[key][i])
WITH e, i
CALL (e, i) {
  UNWIND $entities[i] AS entity
  MATCH (n) WHERE id(n) = entity
  CREATE (e)-[:CORR]->(n)
}
CALL (e, i) {
  UNWIND $classes[i] AS class
  MATCH (c) WHERE id(c) = class
  CREATE (e)-[:OBSERVED]->(c)
}
RETURN collect([i, id(e)]) AS nodes
