// Record step $step of the aggregation of log $log ($spec: the step as JSON text) while its
// aggregates are written; `status` becomes 'complete' with them.
CREATE (s:AggregationStep {log: $log, step: $step, spec: $spec, status: 'writing',
                           created: datetime()})
