// Remove DF edges of a live log that no longer join consecutive events of their entity (an
// event heard late now lies between them): from $sources[i] to $targets[i] (element ids) for
// the entity ($entityTypes[i], $entityIds[i]).
UNWIND range(0, size($sources) - 1) AS i
MATCH (a:Event)-[r:DF]->(b:Event)
WHERE elementId(a) = $sources[i] AND elementId(b) = $targets[i] AND a.log = $log
      AND r.entityType = $entityTypes[i] AND r.entityId = $entityIds[i]
DELETE r
