// Remove BEGINS edges of a live log that its events no longer give (an event heard late is
// now an entity's first): from the entity $entities[i] to the class $classes[i] (element ids).
UNWIND range(0, size($entities) - 1) AS i
MATCH (n:Entity)-[b:BEGINS]->(c:Class)
WHERE elementId(n) = $entities[i] AND elementId(c) = $classes[i] AND n.log = $log
DELETE b
