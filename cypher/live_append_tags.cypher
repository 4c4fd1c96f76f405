// Tags of a live run, stored in one transaction as the monitor's writer takes them (a few
// tenths of a second of the run each): $seqs[i] numbers the i-th in arrival order.
UNWIND range(0, size($seqs) - 1) AS i
CREATE (:LiveTag {
  log: $log, seq: $seqs[i], stamp: $stamps[i], robot: $robots[i], activity: $activities[i],
  lifecycle: $lifecycles[i], msgId: $msgIds[i], msgRole: $msgRoles[i], payload: $payloads[i]
})
