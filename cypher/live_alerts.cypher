// The alerts raised so far for the live run $log, oldest first.
MATCH (a:LiveAlert {log: $log})
RETURN a.stamp AS stamp, a.kind AS kind, a.robot AS robot, a.text AS text
ORDER BY a.stamp
