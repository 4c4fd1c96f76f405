// Which build of the log $log is stored (no row when there is none): its status, when its Log
// node was created and by which run, when runs were last appended to it, the event properties
// it stores and the column types of the event table it was built from (an Arrow schema, or
// null when it was not recorded).
MATCH (l:Log {name: $log})
RETURN l.status AS status, toString(l.created) AS created, l.run AS run,
       toString(l.appended) AS appended, l.properties AS properties, l.columns AS columns
