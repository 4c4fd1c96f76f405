// Whether log $log records where its entities begin for the classes of type $type (logs stored
// by earlier versions of robotale have classes but no BEGINS edges).
RETURN EXISTS {
  MATCH (:Entity {log: $log})-[:BEGINS]->(:Class {log: $log, type: $type})
} OR NOT EXISTS {
  MATCH (:Entity {log: $log})
} AS recorded
