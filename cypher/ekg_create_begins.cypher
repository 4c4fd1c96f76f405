// Where entities begin in a new log: BEGINS edges from entities (element ids $entities[i]) to
// the classes of the first event of their chain in a case ($classes[i]), with the number of
// $cases in which they began there (appends use ekg_merge_begins).
UNWIND range(0, size($entities) - 1) AS i
MATCH (n) WHERE elementId(n) = $entities[i]
MATCH (c) WHERE elementId(c) = $classes[i]
CREATE (n)-[:BEGINS {cases: $cases[i]}]->(c)
