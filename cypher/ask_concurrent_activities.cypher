// The activities robots $robot and $other of log $log did at the same time: each pair of
// their activity instances (a start with the next completion of the same activity by the
// same robot in the same run) that overlap, with the seconds they overlap.
MATCH (e:Event {log: $log})
WHERE e.robot IN [$robot, $other] AND e.lifecycle IN ['start', 'complete']
// each robot's starts and completions of one activity in one run
WITH e.case AS run, e.robot AS robot, e.activity AS activity,
     collect(CASE e.lifecycle WHEN 'start' THEN e.timestamp END) AS starts,
     collect(CASE e.lifecycle WHEN 'complete' THEN e.timestamp END) AS completions
UNWIND starts AS begins
// the instance ends at the first completion at or after its start
WITH run, robot, activity, begins,
     reduce(first = null, c IN completions |
            CASE WHEN c >= begins AND (first IS NULL OR c < first) THEN c ELSE first END) AS ends
WHERE ends IS NOT NULL
WITH run, collect({robot: robot, activity: activity, begins: begins, ends: ends}) AS spans
WITH run, [a IN spans WHERE a.robot = $robot] AS mine, [b IN spans WHERE b.robot = $other] AS theirs
UNWIND mine AS a
// the other robot's instances that overlap this one
UNWIND [b IN theirs WHERE b.begins < a.ends AND a.begins < b.ends] AS b
WITH run, a, b,
     CASE WHEN a.begins > b.begins THEN a.begins ELSE b.begins END AS overlap_begins,
     CASE WHEN a.ends < b.ends THEN a.ends ELSE b.ends END AS overlap_ends
RETURN run, a.activity AS activity, b.activity AS other_activity,
       toString(overlap_begins) AS from,
       duration.inSeconds(overlap_begins, overlap_ends).seconds AS seconds
// in time order (with the run first, Neo4j sorted rows still holding every span: MBs each)
ORDER BY from, run
