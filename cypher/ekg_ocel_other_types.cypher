// The first of the objects ($types[i], $ids[i]) whose id log $log already holds as an entity
// of another of its types $entityTypes (no row when none): an object-centric log's ids name
// one object each, so an append may not give a stored object another type.
UNWIND range(0, size($ids) - 1) AS i
UNWIND $entityTypes AS stored
WITH i, stored WHERE stored <> $types[i]
MATCH (n:Entity {log: $log, type: stored, id: $ids[i]})
RETURN $ids[i] AS id, $types[i] AS given, n.type AS stored
LIMIT 1
