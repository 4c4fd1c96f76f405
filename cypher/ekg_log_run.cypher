// The run (write lock id) that wrote the Log node of $log (no row when there is none).
MATCH (l:Log {name: $log})
RETURN l.run AS run
