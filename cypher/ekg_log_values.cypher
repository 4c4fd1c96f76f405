// The values a log $log offers to filter by: its cases, robots, robot types and activities,
// and how many events it has (the dashboard's Discover filters). Read from the Log node,
// which records them when the log is stored; counted from the events of a log that does not
// (one still being built).
OPTIONAL MATCH (l:Log {name: $log})
OPTIONAL CALL (l) {
  WITH l WHERE l IS NULL OR l.activities IS NULL
  MATCH (e:Event {log: $log})
  RETURN collect(DISTINCT e.case) AS cases, collect(DISTINCT e.robot) AS robots,
         collect(DISTINCT e.robot_type) AS robotTypes, collect(DISTINCT e.activity) AS activities,
         count(e) AS events
}
RETURN coalesce(l.cases, cases) AS case, coalesce(l.robots, robots) AS robot,
       coalesce(l.robotTypes, robotTypes) AS robot_type,
       coalesce(l.activities, activities) AS activity,
       CASE WHEN l.activities IS NULL THEN events ELSE l.events END AS events
