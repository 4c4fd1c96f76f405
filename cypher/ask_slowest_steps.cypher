// The $top (default 10) slowest steps between classes of type $classType (default
// "activity+robot") of log $log: the DF edges between their events within one run (a step
// over a night between two runs is no step), how often each was taken, its median and mean
// seconds.
WITH coalesce($classType, 'activity+robot') AS classType
MATCH (c1:Class {log: $log, type: classType})<-[:OBSERVED]-(e1:Event)-[df:DF]->(e2:Event)
      -[:OBSERVED]->(c2:Class {log: $log, type: classType})
WHERE e1.case = e2.case
WITH c1, c2, df.entityType AS entity_type,
     (e2.timestamp.epochMillis - e1.timestamp.epochMillis) / 1000.0 AS seconds
RETURN c1.id AS source, c2.id AS target, entity_type, count(*) AS count,
       percentileCont(seconds, 0.5) AS median_seconds, avg(seconds) AS mean_seconds
ORDER BY median_seconds DESC, count DESC
LIMIT coalesce($top, 10)
