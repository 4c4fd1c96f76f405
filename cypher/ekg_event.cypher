// One event of log $log by its id, with all its properties.
MATCH (e:Event {log: $log, id: $id})
RETURN e
