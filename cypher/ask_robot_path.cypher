// The path of robot $robot in run $case of log $log: every activity it started (or did at
// once), in the order it did them, and the seconds until its next one along its DF edges.
MATCH (e:Event {log: $log, robot: $robot})
WHERE toString(e.case) = toString($case)
  AND coalesce(e.lifecycle, 'none') <> 'complete'
  AND coalesce(e.state, 'none') <> 'inprogress'
OPTIONAL MATCH (e)-[:DF {entityType: 'robot'}]->(next:Event)
RETURN e.activity AS activity, e.lifecycle AS lifecycle, toString(e.timestamp) AS time,
       duration.inSeconds(e.timestamp, next.timestamp).seconds AS seconds_to_next
ORDER BY e.timestamp, e.order
