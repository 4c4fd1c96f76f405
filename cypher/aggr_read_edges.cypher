// The edges of log $log an aggregation step lifts, from the events at positions $first up to
// (not including) $last, as columns (one row: less to send than a row per edge): every CORR,
// DF and COMM edge from an event to a node of the log (CORR to an entity, DF and COMM to an
// event) as the build wrote them, with their kind and, for DF, their entity type ('' for the
// others: collect leaves nulls out). Lifted edges end at an Aggregate, so none of them is
// read. One expansion over the three types: a subquery per event and kind costs twice as
// much. Read a range of events at a time: the whole log's edges in one row would outgrow a
// transaction's memory.
MATCH (e:Event)-[r:CORR|DF|COMM]->(target)
WHERE e.log = $log AND e.order >= $first AND e.order < $last AND NOT target:Aggregate
RETURN collect(type(r)) AS kinds, collect(elementId(e)) AS sources,
       collect(elementId(target)) AS targets, collect(CASE type(r) WHEN 'DF' THEN coalesce(r.entityType, '') ELSE '' END) AS entityTypes
