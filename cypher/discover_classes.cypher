// The classes of log $log for the class type $type ("activity", "activity+robot" ...): each
// with its key values, how many events it aggregates and the robots that performed them.
MATCH (c:Class {log: $log, type: $type})
CALL (c) {
  MATCH (c)<-[:OBSERVED]-(e:Event)
  RETURN count(e) AS events, collect(DISTINCT e.robot) AS robots
}
RETURN c.id AS id, properties(c) AS properties, events, robots
ORDER BY id
