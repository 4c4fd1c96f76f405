// AGGREGATED_IN edges from the nodes a step collapses to their aggregates (node ids
// $members[i] -> $aggregates[i]).
UNWIND range(0, size($members) - 1) AS i
MATCH (n) WHERE id(n) = $members[i]
MATCH (a) WHERE id(a) = $aggregates[i]
CREATE (n)-[:AGGREGATED_IN]->(a)
