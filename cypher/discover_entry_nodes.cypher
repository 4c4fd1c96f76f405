// Where each entity of type $entityType in log $log begins: the class (of type $type) of the
// first event of its chain, and in how many cases it began there (thesis figure 7.7). Stored
// as BEGINS edges when the classes are built, so nothing is computed here.
MATCH (n:Entity {log: $log, type: $entityType})-[b:BEGINS]->(c:Class {log: $log, type: $type})
RETURN n.id AS entity, c.id AS class, b.cases AS cases
ORDER BY entity, class
