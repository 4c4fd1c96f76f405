// The steps $steps of the aggregation of log $log are written: record each one's counts
// ($steps: [{step, aggregates, members}]), all of a run's steps in one write at its end.
UNWIND $steps AS done
MATCH (s:AggregationStep {log: $log, step: done.step})
SET s.aggregates = done.aggregates, s.members = done.members, s.status = 'complete'
