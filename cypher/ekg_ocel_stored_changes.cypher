// Which of the attribute changes given as columns (as in ekg_object_changes) the log $log
// already holds: the row numbers i whose object has an AttributeChange with the same field,
// time and value (an object-centric append writes only the others).
UNWIND range(0, size($objects) - 1) AS i
MATCH (n:Entity {log: $log, type: $types[i], id: $objects[i]})-[:CHANGED]->
      (c:AttributeChange {field: $fields[i], time: $times[i]})
WHERE c.value = $values[i]
RETURN DISTINCT i
