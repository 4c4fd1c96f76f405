// Give the log stored as $log the name $name (used by --replace once the new log is complete).
// Batched: run it as an auto-commit query (in Neo4j Browser: prefix :auto).
MATCH (e:Event) WHERE e.log = $log AND e.id IS NOT NULL
CALL (e) { SET e.log = $name } IN TRANSACTIONS OF 10000 ROWS;
MATCH (n:Entity) WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL
CALL (n) { SET n.log = $name } IN TRANSACTIONS OF 10000 ROWS;
MATCH (c:Class) WHERE c.log = $log AND c.type IS NOT NULL AND c.id IS NOT NULL
CALL (c) { SET c.log = $name } IN TRANSACTIONS OF 10000 ROWS;
MATCH (l:Log {name: $log})
SET l.name = $name;
