// Give BEGINS edges of a live log the number of cases in which their entity now begins at
// their class: from the entity $entities[i] to the class $classes[i] (element ids).
UNWIND range(0, size($entities) - 1) AS i
MATCH (n:Entity)-[b:BEGINS]->(c:Class)
WHERE elementId(n) = $entities[i] AND elementId(c) = $classes[i] AND n.log = $log
SET b.cases = $cases[i]
