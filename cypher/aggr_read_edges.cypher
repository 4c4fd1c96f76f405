// The edges of log $log an aggregation step lifts, as columns (one row: less to send than a
// row per edge): every CORR edge from an event to an entity and every DF and COMM edge
// between two events, as the build wrote them (lifted edges end at an Aggregate, so none of
// them is read), with their kind and, for DF, their entity type ('' for the others: collect
// leaves nulls out).
CALL () {
  MATCH (e:Event)-[:CORR]->(n:Entity)
  WHERE e.log = $log
  RETURN 'CORR' AS kind, e AS source, n AS target, '' AS entityType
  UNION ALL
  MATCH (e:Event)-[r:DF]->(f:Event)
  WHERE e.log = $log
  RETURN 'DF' AS kind, e AS source, f AS target, coalesce(r.entityType, '') AS entityType
  UNION ALL
  MATCH (e:Event)-[:COMM]->(f:Event)
  WHERE e.log = $log
  RETURN 'COMM' AS kind, e AS source, f AS target, '' AS entityType
}
RETURN collect(kind) AS kinds, collect(elementId(source)) AS sources,
       collect(elementId(target)) AS targets, collect(entityType) AS entityTypes
