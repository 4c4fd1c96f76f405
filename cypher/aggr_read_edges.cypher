// The edges of log $log an aggregation step lifts, from the events at positions $first up to
// (not including) $last, as columns (one row: less to send than a row per edge): every CORR
// edge from an event to an entity and every DF and COMM edge between two events, as the build
// wrote them (lifted edges end at an Aggregate, so none of them is read), with their kind and,
// for DF, their entity type ('' for the others: collect leaves nulls out). Read a range of
// events at a time: the whole log's edges in one row would outgrow a transaction's memory.
MATCH (e:Event)
WHERE e.log = $log AND e.order >= $first AND e.order < $last
CALL (e) {
  MATCH (e)-[:CORR]->(n:Entity)
  RETURN 'CORR' AS kind, n AS target, '' AS entityType
  UNION ALL
  MATCH (e)-[r:DF]->(f:Event)
  RETURN 'DF' AS kind, f AS target, coalesce(r.entityType, '') AS entityType
  UNION ALL
  MATCH (e)-[:COMM]->(f:Event)
  RETURN 'COMM' AS kind, f AS target, '' AS entityType
}
RETURN collect(kind) AS kinds, collect(elementId(e)) AS sources,
       collect(elementId(target)) AS targets, collect(entityType) AS entityTypes
