// The aggregation steps of log $log, in order, with what each recorded.
MATCH (s:AggregationStep)
WHERE s.log = $log AND s.step IS NOT NULL
RETURN s.step AS step, s.spec AS spec, s.status AS status, s.aggregates AS aggregates,
       s.members AS members, toString(s.created) AS created
ORDER BY step
