// The odometry samples stored so far for the live run $log, oldest first (by robot where two
// share a time).
MATCH (p:LivePose {log: $log})
RETURN p.robot AS robot, p.stamp AS stamp, p.x AS x, p.y AS y, p.z AS z
ORDER BY p.stamp, p.robot
