// Which aggregate of log $log holds each node that earlier steps collapsed, so a step stacked
// on them lifts its edges to those aggregates: the aggregates' ids and element ids, and the
// collapsed nodes' element ids with the id in their `_aggregate`.
CALL () {
  MATCH (a:Aggregate)
  WHERE a.log = $log AND a.id IS NOT NULL
  RETURN collect(a.id) AS ids, collect(elementId(a)) AS aggregates
}
CALL () {
  CALL () {
    MATCH (n:Event)
    WHERE n.log = $log AND n.id IS NOT NULL AND n._aggregate IS NOT NULL
    RETURN n
    UNION ALL
    MATCH (n:Entity)
    WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL AND n._aggregate IS NOT NULL
    RETURN n
  }
  RETURN collect(elementId(n)) AS nodes, collect(n._aggregate) AS held
}
RETURN ids, aggregates, nodes, held
