// Aggregate the events of log $log into Class nodes by the key $key, a list of event
// properties such as ["activity"] or ["activity", "robot"]; $type names the key
// ("activity+robot"). A class holds the key's values as properties and as its id
// ("move|tractor_1"); each event gets an OBSERVED edge to its class. Batched: run it as an
// auto-commit query (in Neo4j Browser: prefix :auto).
MATCH (e:Event) WHERE e.log = $log AND e.id IS NOT NULL
WITH [k IN $key | e[k]] AS values, collect(e) AS events
UNWIND range(0, size(events) - 1, 10000) AS start
CALL (values, events, start) {
  MERGE (c:Class {log: $log, type: $type,
                  id: reduce(id = '', i IN range(0, size(values) - 1) |
                        id + CASE WHEN i > 0 THEN '|' ELSE '' END + coalesce(toString(values[i]), ''))})
  ON CREATE SET c.key = $key
  FOREACH (i IN range(0, size($key) - 1) | SET c[$key[i]] = values[i])
  WITH c
  UNWIND events[start..start + 10000] AS e
  CREATE (e)-[:OBSERVED]->(c)
} IN TRANSACTIONS OF 1 ROWS
