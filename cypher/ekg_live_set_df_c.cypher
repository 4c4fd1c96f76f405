// Give DF_C edges of a live log whose instances changed their new count and mean and median
// seconds: from the class $sources[i] to $targets[i] (element ids) for the entity type
// $entityTypes[i]; the edges the update leaves as they were are not touched.
UNWIND range(0, size($sources) - 1) AS i
MATCH (a:Class)-[r:DF_C]->(b:Class)
WHERE elementId(a) = $sources[i] AND elementId(b) = $targets[i] AND a.log = $log
      AND r.entityType = $entityTypes[i]
SET r.count = $counts[i], r.meanSeconds = $means[i], r.medianSeconds = $medians[i]
