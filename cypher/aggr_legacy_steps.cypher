// The complete aggregation steps $step, $step + 1 ... of log $log whose aggregates list no
// members (AggregateMembers): steps written by earlier versions of robotale, which marked each
// member with its aggregate's id in its property `_aggregate` (or linked it by an
// AGGREGATED_IN edge). A step cut short while writing is no such step.
MATCH (s:AggregationStep)
WHERE s.log = $log AND s.step >= $step AND s.status = 'complete'
MATCH (a:Aggregate)
WHERE a.log = $log AND a.step = s.step AND a.id IS NOT NULL
  AND NOT EXISTS {
    MATCH (m:AggregateMembers)
    WHERE m.log = $log AND m.step = a.step AND m.id = a.id
  }
WITH DISTINCT a.step AS step ORDER BY step
RETURN collect(step) AS steps
