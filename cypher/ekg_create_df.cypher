// DF edges between consecutive events of one entity (node ids $sources[i] -> $targets[i]).
UNWIND range(0, size($sources) - 1) AS i
MATCH (a) WHERE id(a) = $sources[i]
MATCH (b) WHERE id(b) = $targets[i]
CREATE (a)-[:DF {entityType: $entityType, entityId: $entityIds[i]}]->(b)
