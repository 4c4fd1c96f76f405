// DF_C edges between classes (element ids $sources[i] -> $targets[i]) for the entity type
// $entityTypes[i]: how many DF edges they aggregate and the mean and median seconds between
// their events, computed from the events before they were written.
UNWIND range(0, size($sources) - 1) AS i
MATCH (a) WHERE elementId(a) = $sources[i]
MATCH (b) WHERE elementId(b) = $targets[i]
CREATE (a)-[:DF_C {entityType: $entityTypes[i], count: $counts[i], meanSeconds: $means[i],
                   medianSeconds: $medians[i]}]->(b)
