// AGGREGATED_IN edges from the nodes a step collapses to their aggregates (element ids
// $members[i] -> $aggregates[i]).
UNWIND range(0, size($members) - 1) AS i
MATCH (n) WHERE elementId(n) = $members[i]
MATCH (a) WHERE elementId(a) = $aggregates[i]
CREATE (n)-[:AGGREGATED_IN]->(a)
