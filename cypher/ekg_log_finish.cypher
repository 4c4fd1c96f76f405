// Mark a log complete and record what the pages open with: $summary holds the number of
// events and the distinct cases, robots, robotTypes and activities (as text).
MATCH (l:Log {name: $log})
SET l += $summary, l.status = 'complete', l.finished = datetime()
