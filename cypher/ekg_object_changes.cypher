// One batch of the attribute changes of the objects of log $log: the Entity ($types[i],
// $objects[i]) gets a CHANGED edge to a new AttributeChange node holding the attribute's
// name $fields[i], its new value $values[i] (of the attribute's own type) and the time
// $times[i] from which it holds. A node per change, not a property: an attribute may change
// many times, and a Neo4j list cannot hold values of several types.
UNWIND range(0, size($objects) - 1) AS i
MATCH (n:Entity {log: $log, type: $types[i], id: $objects[i]})
CREATE (n)-[:CHANGED]->(:AttributeChange {log: $log, field: $fields[i], value: $values[i],
                                           time: $times[i]})
