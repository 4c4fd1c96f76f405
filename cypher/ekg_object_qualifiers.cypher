// One batch of the qualifiers of event-to-object relations of log $log: the CORR edge from
// the event $events[i] to the Entity ($types[i], $objects[i]) gets the list $qualifiers[i].
UNWIND range(0, size($events) - 1) AS i
MATCH (e:Event {log: $log, id: $events[i]})-[c:CORR]->
      (n:Entity {log: $log, type: $types[i], id: $objects[i]})
SET c.qualifiers = $qualifiers[i]
