// Which nodes the aggregates of step $step of log $log replace: for each aggregate id
// $aggregates[i], one part ($parts[i]) of the ids of its members $members[i] (events by their
// id; entities, all of the aggregate's type, by theirs). One list per aggregate rather than a
// mark or an edge per member: a step may collapse a million nodes, and Neo4j writes one long
// list far faster than a million small changes, while undo removes the step with it. Find an
// aggregate's events with
// MATCH (m:AggregateMembers {log: $log, id: $id}) UNWIND m.members AS member
// MATCH (e:Event {log: $log, id: member}).
UNWIND range(0, size($aggregates) - 1) AS i
CREATE (:AggregateMembers {log: $log, step: $step, id: $aggregates[i], part: $parts[i],
                           members: $members[i]})
