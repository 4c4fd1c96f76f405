// Which aggregate of log $log holds each node that earlier steps collapsed, so a step stacked
// on them lifts its edges to those aggregates: the aggregates' ids and element ids, and the
// collapsed nodes by key (the entity type, null for an event, and the id) with the id in their
// `_aggregate`.
CALL () {
  MATCH (a:Aggregate)
  WHERE a.log = $log AND a.id IS NOT NULL
  RETURN collect(a.id) AS ids, collect(elementId(a)) AS aggregates
}
CALL () {
  CALL () {
    MATCH (n:Event)
    WHERE n.log = $log AND n.id IS NOT NULL AND n._aggregate IS NOT NULL
    RETURN null AS type, n
    UNION ALL
    MATCH (n:Entity)
    WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL AND n._aggregate IS NOT NULL
    RETURN n.type AS type, n
  }
  RETURN collect(type) AS types, collect(n.id) AS keys, collect(n._aggregate) AS held
}
RETURN ids, aggregates, types, keys, held
