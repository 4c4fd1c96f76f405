// The class graph of log $log for the class type $type ("activity", "activity+robot") and the
// entity type $entityType: every DF_C edge with the properties of its two classes.
MATCH (a:Class {log: $log, type: $type})-[r:DF_C {entityType: $entityType}]->(b:Class)
RETURN properties(a) AS source, properties(b) AS target, r.count AS count,
       r.meanSeconds AS meanSeconds, r.medianSeconds AS medianSeconds
ORDER BY count DESC, source.id, target.id
