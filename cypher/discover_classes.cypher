// The classes of log $log for the class type $type ("activity", "activity+robot" ...): each
// with its key values, how many events it aggregates, how many of them are activity
// instances (the event that ends one: a completion, an aborted or cancelled end, or an
// instant event; never a start or an in-progress sample), how many are in-progress samples,
// and the robots that performed them.
MATCH (c:Class {log: $log, type: $type})
CALL (c) {
  MATCH (c)<-[:OBSERVED]-(e:Event)
  WITH e, coalesce(e.state, 'none') = 'inprogress' AS sample
  RETURN count(e) AS events,
         count(CASE WHEN NOT sample AND coalesce(e.lifecycle, 'complete') <> 'start'
                    THEN 1 END) AS instances,
         count(CASE WHEN sample THEN 1 END) AS samples,
         collect(DISTINCT e.robot) AS robots
}
RETURN c.id AS id, properties(c) AS properties, events, instances, samples, robots
ORDER BY id
