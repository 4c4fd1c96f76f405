// Record on the Log node of $log what it holds after runs were appended: $summary as in
// ekg_log_finish, for the whole log.
MATCH (l:Log {name: $log})
SET l += $summary, l.appended = datetime()
