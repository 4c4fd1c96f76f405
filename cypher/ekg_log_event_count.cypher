// How many events of log $log are stored so far (the dashboard's progress while it is built).
MATCH (e:Event {log: $log})
RETURN count(e) AS events
