// Whether anything is stored under the log name $log (a Log node or events).
// `e.id IS NOT NULL` lets the (log, id) index find the events.
RETURN EXISTS { MATCH (l:Log {name: $log}) }
    OR EXISTS { MATCH (e:Event) WHERE e.log = $log AND e.id IS NOT NULL } AS exists
