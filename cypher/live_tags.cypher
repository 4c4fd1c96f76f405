// The tags stored so far for the live run $log, in the order the monitor heard them.
MATCH (t:LiveTag {log: $log})
RETURN t.seq AS seq, t.stamp AS stamp, t.robot AS robot, t.activity AS activity,
       t.lifecycle AS lifecycle, t.msgId AS msgId, t.msgRole AS msgRole, t.payload AS payload
ORDER BY t.seq
