// Forget the live run $log (its tags, odometry samples and alerts): a monitor starting a run
// of that name.
MATCH (n) WHERE (n:LiveTag OR n:LivePose OR n:LiveAlert) AND n.log = $log
DETACH DELETE n
