// Where the entities of log $log begin, for the classes of type $type of a stored log: a
// BEGINS edge from each entity to the class of each event no DF edge of that entity leads to
// (the first of its chain in a case), with the number of cases in which it began there
// (thesis figure 7.7).
MATCH (n:Entity) WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL
MATCH (n)<-[:CORR]-(e:Event)
WHERE NOT EXISTS {
  MATCH (:Event)-[:DF {entityType: n.type, entityId: n.id}]->(e)
}
MATCH (e)-[:OBSERVED]->(c:Class {log: $log, type: $type})
WITH n, c, count(*) AS cases
CREATE (n)-[:BEGINS {cases: cases}]->(c)
