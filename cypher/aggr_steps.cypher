// The aggregation steps of log $log, in order, with what each recorded; `run`: the first step
// of the specification it was run with (steps written before runs were recorded: their own).
MATCH (s:AggregationStep)
WHERE s.log = $log AND s.step IS NOT NULL
RETURN s.step AS step, s.spec AS spec, s.status AS status, s.aggregates AS aggregates,
       s.members AS members, toString(s.created) AS created, coalesce(s.run, s.step) AS run
ORDER BY step
