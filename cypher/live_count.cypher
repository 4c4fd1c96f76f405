// How many tags and odometry samples the live run $log holds so far (0 when there is no such
// run): a reader rebuilds its copy of the run only when one of them grew.
CALL () { MATCH (t:LiveTag {log: $log}) RETURN count(t) AS tags }
CALL () { MATCH (p:LivePose {log: $log}) RETURN count(p) AS poses }
RETURN tags, poses
