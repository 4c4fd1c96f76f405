// Step $step of the aggregation of log $log is written: record its counts ($counts).
MATCH (s:AggregationStep {log: $log, step: $step})
SET s += $counts, s.status = 'complete'
