// Remove events of a live log (element ids $nodes) that the log as it stands now no longer
// holds, with their edges; then the entities and classes no event of the log leads to.
UNWIND $nodes AS node
MATCH (e:Event) WHERE elementId(e) = node AND e.log = $log
DETACH DELETE e;
MATCH (n:Entity {log: $log}) WHERE NOT EXISTS { (n)<-[:CORR]-(:Event) }
DETACH DELETE n;
MATCH (c:Class {log: $log}) WHERE NOT EXISTS { (c)<-[:OBSERVED]-(:Event) }
DETACH DELETE c
