// Every event of log $log in the order of the log, in chunks of 2,000: per chunk the events'
// properties, their times as Unix seconds and nanoseconds, and the zones they were given in.
// The timestamp itself stays out of the properties (turning 100k Neo4j datetimes into Python
// objects costs seconds), and chunks rather than one row per event spare the client 100k
// round trips through the driver: 100k events read in about a seventh of the time.
MATCH (e:Event {log: $log})
WITH e ORDER BY e.order
WITH collect(e) AS events
UNWIND range(0, size(events) - 1, 2000) AS first
WITH events[first..first + 2000] AS chunk
RETURN [e IN chunk | e {.*, timestamp: null, log: null, order: null}] AS properties,
       [e IN chunk | e.timestamp.epochSeconds] AS seconds,
       [e IN chunk | e.timestamp.nanosecond] AS nanos,
       [e IN chunk | e.timestamp.timezone] AS zones
