// The messages of log $log: each COMM edge with the sending and the receiving activity.
MATCH (s:Event)-[r:COMM]->(t:Event)
WHERE s.log = $log AND s.id IS NOT NULL
RETURN s.activity AS sender, t.activity AS receiver, r.msgId AS msgId,
       s.msg_id AS sendMsgId, t.msg_id AS receiveMsgId, s.robot AS fromRobot, t.robot AS toRobot
ORDER BY msgId
