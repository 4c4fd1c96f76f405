// The messages of log $log that were sent and never received (no COMM edge from any of their
// events), and the next $following (default 3) activities their sender started after sending
// them.
CALL () {
  // every message received in each run, gathered once rather than looked up per message
  MATCH (r:Event {log: $log})
  WHERE r.msg_id IS NOT NULL AND r.activity ENDS WITH '?'
  RETURN collect(DISTINCT [r.case, r.msg_id]) AS received
}
MATCH (s:Event {log: $log})
WHERE s.msg_id IS NOT NULL AND s.activity ENDS WITH '!'
WITH received, s.case AS run, s.msg_id AS message, s.activity AS activity, s.robot AS sender,
     min(s.timestamp) AS sent, collect(s) AS sends
WHERE NONE(send IN sends WHERE (send)-[:COMM]->()) AND NOT [run, message] IN received
CALL (run, sender, sent) {
  MATCH (n:Event {log: $log, robot: sender})
  WHERE n.case = run AND n.timestamp > sent
    AND coalesce(n.lifecycle, 'none') <> 'complete'
    AND coalesce(n.state, 'none') <> 'inprogress'
  WITH n ORDER BY n.timestamp, n.order LIMIT coalesce($following, 3)
  RETURN collect(n.activity) AS then
}
RETURN run, message, activity, sender, toString(sent) AS sent, then
ORDER BY sent
