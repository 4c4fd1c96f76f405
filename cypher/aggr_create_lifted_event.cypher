// One batch of the lifted edges of aggregation step $step between an aggregate (element id
// $aggregates[i]) and an event no aggregate holds, found by its key: the event of log $log with
// the id $nodes[i] (aggr_create_lifted_entity: the same for entities). The edge leaves the
// aggregate when $outgoing[i], else it enters it; its kind $kinds[i] ('CORR', 'DF' or 'COMM'),
// standing for $counts[i] edges of the log, a DF edge with its entity type $entityTypes[i].
// Found by key rather than element id: robotale computes the edges from the log's event
// table, so it knows the nodes' ids but not their element ids.
UNWIND range(0, size($aggregates) - 1) AS i
MATCH (a) WHERE elementId(a) = $aggregates[i]
MATCH (n:Event {log: $log, id: $nodes[i]})
WITH i, CASE WHEN $outgoing[i] THEN a ELSE n END AS s, CASE WHEN $outgoing[i] THEN n ELSE a END AS t
FOREACH (_ IN CASE WHEN $kinds[i] = 'CORR' THEN [1] ELSE [] END |
  CREATE (s)-[:CORR {step: $step, count: $counts[i]}]->(t))
FOREACH (_ IN CASE WHEN $kinds[i] = 'DF' THEN [1] ELSE [] END |
  CREATE (s)-[:DF {step: $step, entityType: $entityTypes[i], count: $counts[i]}]->(t))
FOREACH (_ IN CASE WHEN $kinds[i] = 'COMM' THEN [1] ELSE [] END |
  CREATE (s)-[:COMM {step: $step, count: $counts[i]}]->(t))
