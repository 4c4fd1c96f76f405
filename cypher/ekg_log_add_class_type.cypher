// Record on the Log node that log $log has classes of type $type.
MATCH (l:Log {name: $log})
SET l.classTypes = [t IN coalesce(l.classTypes, []) WHERE t <> $type] + [$type]
