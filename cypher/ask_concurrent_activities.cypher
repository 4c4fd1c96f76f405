// The activities robots $robot and $other of log $log did at the same time: each pair of
// their activity instances (a start with the next completion of the same activity by the
// same robot in the same run) that overlap, with the seconds they overlap.
MATCH (s:Event {log: $log, lifecycle: 'start'})
WHERE s.robot IN [$robot, $other]
CALL (s) {
  MATCH (c:Event {log: $log, lifecycle: 'complete', robot: s.robot, activity: s.activity})
  WHERE c.case = s.case AND c.timestamp >= s.timestamp
  RETURN c.timestamp AS ends ORDER BY c.timestamp, c.order LIMIT 1
}
WITH s.case AS run, collect({robot: s.robot, activity: s.activity, begins: s.timestamp,
                             ends: ends}) AS spans
UNWIND [a IN spans WHERE a.robot = $robot] AS a
UNWIND [b IN spans WHERE b.robot = $other] AS b
WITH run, a, b,
     CASE WHEN a.begins > b.begins THEN a.begins ELSE b.begins END AS overlap_begins,
     CASE WHEN a.ends < b.ends THEN a.ends ELSE b.ends END AS overlap_ends
WHERE overlap_begins < overlap_ends
RETURN run, a.activity AS activity, b.activity AS other_activity,
       toString(overlap_begins) AS from,
       duration.inSeconds(overlap_begins, overlap_ends).seconds AS seconds
ORDER BY run, from
