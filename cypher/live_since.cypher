// The tags and the odometry samples stored for the live run $log after the first $tags and
// the first $poses (all: 0), each in the order stored: one round trip for a reader that keeps
// what it has and asks only for the new ones (both read by index seeks on (log, seq)).
CALL () {
  MATCH (t:LiveTag {log: $log})
  WHERE t.seq > $tags
  WITH t ORDER BY t.seq
  RETURN collect([t.stamp, t.robot, t.activity, t.lifecycle, t.msgId, t.msgRole, t.payload])
         AS tags
}
CALL () {
  MATCH (p:LivePose {log: $log})
  WHERE p.seq > $poses
  WITH p ORDER BY p.seq
  RETURN collect([p.stamp, p.robot, p.x, p.y, p.z]) AS poses
}
RETURN tags, poses
