// DF_C edges between the classes of type $type in log $log: one per pair of classes and
// entity type, with how many DF edges it aggregates and the mean and median seconds
// between their events (to the nanosecond, as the events' times are stored). $sources: null for every class, or the element ids of the classes
// whose outgoing DF_C edges are (re)computed (those an appended run reaches).
MATCH (c1:Class {log: $log, type: $type})<-[:OBSERVED]-(e1:Event)-[df:DF]->(e2:Event)
      -[:OBSERVED]->(c2:Class {log: $log, type: $type})
WHERE $sources IS NULL OR elementId(c1) IN $sources
WITH c1, c2, df.entityType AS entityType,
     (e2.timestamp.epochSeconds - e1.timestamp.epochSeconds)
     + (e2.timestamp.nanosecond - e1.timestamp.nanosecond) / 1e9 AS seconds
WITH c1, c2, entityType, count(*) AS count,
     avg(seconds) AS meanSeconds, percentileCont(seconds, 0.5) AS medianSeconds
CREATE (c1)-[r:DF_C {entityType: entityType, count: count, meanSeconds: meanSeconds,
                     medianSeconds: medianSeconds}]->(c2)
RETURN count(r) AS edges
