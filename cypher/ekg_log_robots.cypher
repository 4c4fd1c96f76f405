// The robots of log $log: the distinct robot property of its events (the Model page finds the
// collaboration whose pools bind them).
MATCH (e:Event {log: $log})
WHERE e.robot IS NOT NULL
RETURN collect(DISTINCT e.robot) AS robots
