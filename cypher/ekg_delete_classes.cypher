// Remove the classes of type $type of log $log with their OBSERVED and DF_C edges, in small
// transactions. Batched: run it as an auto-commit query (in Neo4j Browser: prefix :auto).
MATCH (c:Class {log: $log, type: $type})<-[r:OBSERVED]-(:Event) WHERE c.id IS NOT NULL
CALL (r) { DELETE r } IN TRANSACTIONS OF 10000 ROWS;
MATCH (c:Class {log: $log, type: $type}) WHERE c.id IS NOT NULL
CALL (c) { DETACH DELETE c } IN TRANSACTIONS OF 1000 ROWS;
