// Where the entities ($types[i], $ids[i]) of log $log begin, for the classes of type $type,
// after an object-centric append chained their events again: their BEGINS edges are
// replaced by one to the class of each event no DF edge of the entity leads to, with the
// number of cases in which it began there (as ekg_aggregate_begins for a whole log).
UNWIND range(0, size($ids) - 1) AS i
MATCH (n:Entity {log: $log, type: $types[i], id: $ids[i]})
OPTIONAL MATCH (n)-[old:BEGINS]->(:Class {log: $log, type: $type})
DELETE old
WITH DISTINCT n
MATCH (n)<-[:CORR]-(e:Event)
WHERE NOT EXISTS {
  MATCH (:Event)-[:DF {entityType: n.type, entityId: n.id}]->(e)
}
MATCH (e)-[:OBSERVED]->(c:Class {log: $log, type: $type})
WITH n, c, count(*) AS cases
CREATE (n)-[:BEGINS {cases: cases}]->(c)
