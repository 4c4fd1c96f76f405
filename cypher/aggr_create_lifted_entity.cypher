// One batch of the lifted edges of aggregation step $step from an aggregate of events (element
// id $aggregates[i]) to an entity no aggregate holds, found by its key: the entity of log $log
// of type $types[i] with the id $nodes[i]. Only CORR edges reach an entity; each stands for
// $counts[i] edges of the log. Found by key rather than element id, as in
// aggr_create_lifted_event.
UNWIND range(0, size($aggregates) - 1) AS i
MATCH (a) WHERE elementId(a) = $aggregates[i]
MATCH (n:Entity {log: $log, type: $types[i], id: $nodes[i]})
CREATE (a)-[:CORR {step: $step, count: $counts[i]}]->(n)
