// One batch of the lifted edges of aggregation step $step: from $sources[i] to $targets[i]
// (element ids of aggregates or nodes) of kind $kinds[i] ('CORR', 'DF' or 'COMM'), standing for
// $counts[i] edges of the log, a DF edge with its entity type $entityTypes[i] (null for the
// others: a null property is not stored). The kind is the relationship's type given as a
// value: one CREATE per row, as the benchmark's floor (aggr_bound_edges) writes, instead of
// three FOREACH, each testing every row's kind with a CASE.
UNWIND range(0, size($sources) - 1) AS i
MATCH (a) WHERE elementId(a) = $sources[i]
MATCH (b) WHERE elementId(b) = $targets[i]
CREATE (a)-[:$($kinds[i]) {step: $step, count: $counts[i], entityType: $entityTypes[i]}]->(b)
