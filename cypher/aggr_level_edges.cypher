// The lifted edges between the aggregates of log $log at level $level: each was written by
// the later step of its two ends, so every one between aggregates of steps <= $level holds.
MATCH (a:Aggregate)-[r:CORR|DF|COMM]->(b:Aggregate)
WHERE a.log = $log AND a.step <= $level AND a.id IS NOT NULL AND b.step <= $level
RETURN a.id AS source, b.id AS target, type(r) AS type, r.entityType AS entityType,
       r.count AS count
ORDER BY source, target, type, entityType
