// Alerts of a live run ($kinds[i]: silence ...), stored in one transaction after they were
// printed and published.
UNWIND range(0, size($stamps) - 1) AS i
CREATE (:LiveAlert {log: $log, stamp: $stamps[i], kind: $kinds[i], robot: $robots[i],
                    text: $texts[i]})
