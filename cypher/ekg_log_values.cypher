// What the Discover page's filters offer for log $log: its cases, robots, robot types and
// activities, and how many events it has.
MATCH (e:Event {log: $log})
RETURN collect(DISTINCT e.case) AS case, collect(DISTINCT e.robot) AS robot,
       collect(DISTINCT e.robot_type) AS robot_type, collect(DISTINCT e.activity) AS activity,
       count(e) AS events
