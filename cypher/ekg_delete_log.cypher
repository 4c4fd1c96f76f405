// Delete one event log: its events, entities and classes with all their relationships, then
// its Log node. Batched, so it needs an auto-commit transaction (in Neo4j Browser: prefix :auto).
MATCH (n:Event {log: $log})
CALL (n) { DETACH DELETE n } IN TRANSACTIONS OF 10000 ROWS;
MATCH (n:Entity {log: $log})
CALL (n) { DETACH DELETE n } IN TRANSACTIONS OF 10000 ROWS;
MATCH (n:Class {log: $log})
CALL (n) { DETACH DELETE n } IN TRANSACTIONS OF 10000 ROWS;
MATCH (n:Log {name: $log})
DETACH DELETE n;
