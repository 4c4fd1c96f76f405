// Remove every DF_C edge between the classes of type $type of log $log, before an
// object-centric append computes them again (new events may extend any object's chain).
MATCH (:Class {log: $log, type: $type})-[r:DF_C]->()
DELETE r
