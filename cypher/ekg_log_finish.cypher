// Mark a log complete and record how many events it has.
MATCH (l:Log {name: $log})
SET l.status = 'complete', l.events = $events, l.finished = datetime()
