// Every event of log $log in the order of the log, as columns in chunks of 20,000 events: per
// chunk one list of values for each property named in $keys (null where an event has none),
// the times as Unix seconds and nanoseconds, and the zone of the chunk's first time. Lists per
// property rather than a map per event spare the driver a key per value.
MATCH (e:Event {log: $log})
WITH e ORDER BY e.order
WITH collect(e) AS events
UNWIND range(0, size(events) - 1, 20000) AS first
WITH events[first..first + 20000] AS chunk
RETURN [key IN $keys | [e IN chunk | e[key]]] AS columns,
       [e IN chunk | e.timestamp.epochSeconds] AS seconds,
       [e IN chunk | e.timestamp.nanosecond] AS nanos,
       chunk[0].timestamp.timezone AS zone
