// Where each entity of type $entityType in log $log begins: the class (of type $type) of its
// first event, the one no DF edge of that entity leads to (thesis figure 7.7).
MATCH (n:Entity {log: $log, type: $entityType})<-[:CORR]-(e:Event)
WHERE NOT EXISTS {
  MATCH (:Event)-[:DF {entityType: $entityType, entityId: n.id}]->(e)
}
MATCH (e)-[:OBSERVED]->(c:Class {log: $log, type: $type})
RETURN n.id AS entity, c.id AS class
ORDER BY entity, class
