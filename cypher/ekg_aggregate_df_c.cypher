// DF_C edges between the classes of type $type in log $log: one per pair of classes and
// entity type, with how many times an activity instance of the one directly followed an
// instance of the other for an entity of that type within a case, and the mean and median
// seconds between the two instances' ends (to the nanosecond, as the events' times are
// stored). An instance is counted once, by the event that ends it: a start and an in-progress
// sample end none (robotale.ekg.tables.instance_ends). Instances follow each other in the
// order of their times, then of their positions in the log, as the DF edges do.
// $sources: null for every class, or the element ids of the classes whose outgoing DF_C
// edges are (re)computed (those an appended run reaches).
MATCH (n:Entity) WHERE n.log = $log AND n.type IS NOT NULL
MATCH (n)<-[:CORR]-(e:Event)
WHERE e.case IS NOT NULL AND coalesce(e.lifecycle, 'complete') <> 'start'
      AND coalesce(e.state, 'none') <> 'inprogress'
WITH n, e ORDER BY e.timestamp, e.order
WITH n, e.case AS case, collect(e) AS chain
UNWIND range(1, size(chain) - 1) AS i
WITH n.type AS entityType, chain[i - 1] AS e1, chain[i] AS e2
MATCH (e1)-[:OBSERVED]->(c1:Class {log: $log, type: $type})
WHERE $sources IS NULL OR elementId(c1) IN $sources
MATCH (e2)-[:OBSERVED]->(c2:Class {log: $log, type: $type})
WITH c1, c2, entityType,
     (e2.timestamp.epochSeconds - e1.timestamp.epochSeconds)
     + (e2.timestamp.nanosecond - e1.timestamp.nanosecond) / 1e9 AS seconds
WITH c1, c2, entityType, count(*) AS count,
     avg(seconds) AS meanSeconds, percentileCont(seconds, 0.5) AS medianSeconds
CREATE (c1)-[r:DF_C {entityType: entityType, count: count, meanSeconds: meanSeconds,
                     medianSeconds: medianSeconds}]->(c2)
RETURN count(r) AS edges
