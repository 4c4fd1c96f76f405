// DF edges between consecutive events of one entity (element ids $sources[i] -> $targets[i]).
UNWIND range(0, size($sources) - 1) AS i
MATCH (a) WHERE elementId(a) = $sources[i]
MATCH (b) WHERE elementId(b) = $targets[i]
CREATE (a)-[:DF {entityType: $entityType, entityId: $entityIds[i]}]->(b)
