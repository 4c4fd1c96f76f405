// The odometry samples stored for the live run $log after the first $after (all: 0), in the
// order they were stored; a reader keeps those it has and asks only for the new ones.
MATCH (p:LivePose {log: $log})
WHERE p.seq > $after
RETURN p.robot AS robot, p.stamp AS stamp, p.x AS x, p.y AS y, p.z AS z
ORDER BY p.seq
