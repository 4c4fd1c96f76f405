// The first of the event ids $ids that log $log already has (no row when none): runs
// appended to a log must bring new ids.
UNWIND $ids AS id
MATCH (e:Event {log: $log, id: id})
RETURN e.id AS id
LIMIT 1
