// One batch of the lifted edges of aggregation step $step: from $sources[i] to $targets[i]
// (element ids of aggregates or nodes) of kind $kinds[i] ('CORR', 'DF' or 'COMM'), standing for
// $counts[i] edges of the log, a DF edge with its entity type $entityTypes[i].
UNWIND range(0, size($sources) - 1) AS i
MATCH (a) WHERE elementId(a) = $sources[i]
MATCH (b) WHERE elementId(b) = $targets[i]
FOREACH (_ IN CASE WHEN $kinds[i] = 'CORR' THEN [1] ELSE [] END |
  CREATE (a)-[:CORR {step: $step, count: $counts[i]}]->(b))
FOREACH (_ IN CASE WHEN $kinds[i] = 'DF' THEN [1] ELSE [] END |
  CREATE (a)-[:DF {step: $step, entityType: $entityTypes[i], count: $counts[i]}]->(b))
FOREACH (_ IN CASE WHEN $kinds[i] = 'COMM' THEN [1] ELSE [] END |
  CREATE (a)-[:COMM {step: $step, count: $counts[i]}]->(b))
