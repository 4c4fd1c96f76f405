// Record step $step of the aggregation of log $log ($spec: the step as JSON text) while its
// aggregates are written; `status` becomes 'complete' with them. $run: the first step of the
// specification it was run with (its steps' lifted edges are those of the level they end at).
CREATE (s:AggregationStep {log: $log, step: $step, spec: $spec, status: 'writing',
                           created: datetime(), run: $run})
