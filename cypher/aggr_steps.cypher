// The aggregation steps of log $log, in order, with what each recorded; `run`: the first step
// of the specification it was run with (steps written before runs were recorded: their own).
// `legacy`: a complete step whose aggregates list no members (AggregateMembers), as earlier
// versions of robotale wrote them: they marked each member with its aggregate's id in its
// property `_aggregate` (or linked it by an AGGREGATED_IN edge). A step cut short while
// writing is no such step.
MATCH (s:AggregationStep)
WHERE s.log = $log AND s.step IS NOT NULL
RETURN s.step AS step, s.spec AS spec, s.status AS status, s.aggregates AS aggregates,
       s.members AS members, toString(s.created) AS created, coalesce(s.run, s.step) AS run,
       s.status = 'complete' AND EXISTS {
         MATCH (a:Aggregate)
         WHERE a.log = $log AND a.step = s.step AND a.id IS NOT NULL
           AND NOT EXISTS {
             MATCH (m:AggregateMembers)
             WHERE m.log = $log AND m.step = a.step AND m.id = a.id
           }
       } AS legacy
ORDER BY step
