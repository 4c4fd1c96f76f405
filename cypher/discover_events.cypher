// Every event of log $log in the order of the log, with its properties; the time as Unix
// seconds and nanoseconds plus the zone it was given in.
MATCH (e:Event {log: $log})
RETURN properties(e) AS properties, e.timestamp.epochSeconds AS seconds,
       e.timestamp.nanosecond AS nanos, e.timestamp.timezone AS zone
ORDER BY e.order
