// One past the last position of the events of log $log (0 for a log without events).
MATCH (e:Event)
WHERE e.log = $log
RETURN coalesce(max(e.order), -1) + 1 AS end
