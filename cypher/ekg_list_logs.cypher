// The logs stored in this database (only $log when it is not null), as their Log nodes
// describe them.
MATCH (l:Log)
WHERE $log IS NULL OR l.name = $log
RETURN l.name AS name, l.status AS status, l.run AS run, l.events AS events, l.source AS source,
       l.entityTypes AS entityTypes, l.classTypes AS classTypes,
       toString(l.created) AS created
ORDER BY name
