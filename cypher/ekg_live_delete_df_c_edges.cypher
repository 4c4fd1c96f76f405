// Remove DF_C edges of a live log that its events no longer give (an event heard late split
// the instances they aggregated): from the class $sources[i] to $targets[i] (element ids) for
// the entity type $entityTypes[i].
UNWIND range(0, size($sources) - 1) AS i
MATCH (a:Class)-[r:DF_C]->(b:Class)
WHERE elementId(a) = $sources[i] AND elementId(b) = $targets[i] AND a.log = $log
      AND r.entityType = $entityTypes[i]
DELETE r
