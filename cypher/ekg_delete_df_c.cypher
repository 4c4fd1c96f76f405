// Remove the outgoing DF_C edges of the classes (element ids $sources) of type $type in log
// $log, before an append computes them again.
MATCH (c:Class {log: $log, type: $type})-[r:DF_C]->()
WHERE elementId(c) IN $sources
DELETE r
