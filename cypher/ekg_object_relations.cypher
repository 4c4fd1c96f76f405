// One batch of object-to-object relations of log $log: a REL edge from the Entity
// ($sourceTypes[i], $sources[i]) to the Entity ($targetTypes[i], $targets[i]) with its
// $qualifiers[i] (null: none).
UNWIND range(0, size($sources) - 1) AS i
MATCH (a:Entity {log: $log, type: $sourceTypes[i], id: $sources[i]})
MATCH (b:Entity {log: $log, type: $targetTypes[i], id: $targets[i]})
CREATE (a)-[:REL {qualifier: $qualifiers[i]}]->(b)
