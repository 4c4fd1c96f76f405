// The aggregates of log $log at level $level (after steps 1 .. $level): every aggregate of
// those steps, since no later step collapses an aggregate.
MATCH (a:Aggregate)
WHERE a.log = $log AND a.step <= $level AND a.id IS NOT NULL
RETURN properties(a) AS aggregate
ORDER BY a.step, a.id
