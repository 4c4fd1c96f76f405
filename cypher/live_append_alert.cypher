// One alert of a live run ($kind: silence ...), stored when the monitor raises it.
CREATE (:LiveAlert {log: $log, stamp: $stamp, kind: $kind, robot: $robot, text: $text})
