// The DF_C edges between the classes of type $type in log $log, for the entity types
// $entityTypes: how often one class directly followed the other for an entity of that type,
// and the mean and median seconds between the two events.
MATCH (a:Class {log: $log, type: $type})-[r:DF_C]->(b:Class {log: $log, type: $type})
WHERE r.entityType IN $entityTypes
RETURN a.id AS source, b.id AS target, r.entityType AS entityType, r.count AS count,
       r.meanSeconds AS meanSeconds, r.medianSeconds AS medianSeconds
ORDER BY entityType, source, target
