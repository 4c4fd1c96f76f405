// Which of the object-to-object relations given as columns (as in ekg_object_relations) the
// log $log already holds: the row numbers i of those it has a REL edge for, with the same
// qualifier (an object-centric append writes only the others).
UNWIND range(0, size($sources) - 1) AS i
MATCH (a:Entity {log: $log, type: $sourceTypes[i], id: $sources[i]})-[r:REL]->
      (b:Entity {log: $log, type: $targetTypes[i], id: $targets[i]})
WHERE r.qualifier = $qualifiers[i] OR (r.qualifier IS NULL AND $qualifiers[i] IS NULL)
RETURN DISTINCT i
