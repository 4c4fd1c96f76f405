// The tags stored for the live run $log after the first $after (all: 0), in the order the
// monitor heard them; a reader keeps those it has and asks only for the new ones.
MATCH (t:LiveTag {log: $log})
WHERE t.seq > $after
RETURN t.seq AS seq, t.stamp AS stamp, t.robot AS robot, t.activity AS activity,
       t.lifecycle AS lifecycle, t.msgId AS msgId, t.msgRole AS msgRole, t.payload AS payload
ORDER BY t.seq
