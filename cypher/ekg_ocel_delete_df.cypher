// Remove the DF edges of the entities ($types[i], $ids[i]) of log $log, before an
// object-centric append chains each entity's stored and new events again.
UNWIND range(0, size($ids) - 1) AS i
MATCH (n:Entity {log: $log, type: $types[i], id: $ids[i]})<-[:CORR]-(:Event)-[r:DF]->()
WHERE r.entityType = n.type AND r.entityId = n.id
DELETE r
