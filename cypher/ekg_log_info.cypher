// What the Log node of $log records (no row when there is no such log): its status, source,
// entity and class types, the event properties it stores, and when it was created.
MATCH (l:Log {name: $log})
RETURN l.name AS name, l.status AS status, l.run AS run, l.events AS events, l.source AS source,
       l.entityTypes AS entityTypes, l.classTypes AS classTypes,
       toString(l.created) AS created, l.properties AS properties
