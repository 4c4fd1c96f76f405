// Where entities begin, in a stored log to which runs are appended: BEGINS edges from
// entities (element ids $entities[i]) to the classes of the first event of their chain in a case
// ($classes[i]); the appended runs' $cases[i] add to an edge that exists (new logs:
// ekg_create_begins).
UNWIND range(0, size($entities) - 1) AS i
MATCH (n) WHERE elementId(n) = $entities[i]
MATCH (c) WHERE elementId(c) = $classes[i]
MERGE (n)-[b:BEGINS]->(c)
ON CREATE SET b.cases = $cases[i]
ON MATCH SET b.cases = b.cases + $cases[i]
