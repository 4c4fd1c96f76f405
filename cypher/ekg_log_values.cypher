// The values a log $log offers to filter by: its cases, robots, robot types and activities,
// and how many events it has (the dashboard's Discover filters).
MATCH (e:Event {log: $log})
RETURN collect(DISTINCT e.case) AS case, collect(DISTINCT e.robot) AS robot,
       collect(DISTINCT e.robot_type) AS robot_type, collect(DISTINCT e.activity) AS activity,
       count(e) AS events
