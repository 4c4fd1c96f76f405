// Remove the BEGINS edges from the entities of log $log to its classes of type $type, before a
// live log's are written again for the events heard so far.
MATCH (:Entity {log: $log})-[b:BEGINS]->(:Class {log: $log, type: $type})
DELETE b
