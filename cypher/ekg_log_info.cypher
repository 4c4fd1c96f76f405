// What the Log node of $log records (null fields when there is no such log).
OPTIONAL MATCH (l:Log {name: $log})
RETURN l.name AS name, l.status AS status, l.properties AS properties,
       l.entityTypes AS entityTypes, l.classTypes AS classTypes
