// Which aggregate of log $log holds each node that earlier steps collapsed (element ids), so
// a step stacked on them lifts its edges to those aggregates.
MATCH (n)-[:AGGREGATED_IN]->(a:Aggregate)
WHERE a.log = $log
RETURN collect(elementId(n)) AS nodes, collect(elementId(a)) AS aggregates
