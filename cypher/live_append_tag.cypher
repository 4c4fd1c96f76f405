// One tag of a live run, stored the moment the monitor hears it (a transaction of its own, so
// the run's log is readable while the run goes on). $seq numbers the tags in arrival order.
CREATE (:LiveTag {
  log: $log, seq: $seq, stamp: $stamp, robot: $robot, activity: $activity,
  lifecycle: $lifecycle, msgId: $msgId, msgRole: $msgRole, payload: $payload
})
