// Odometry samples of a live run's robots, as the monitor keeps them (at a bounded rate per
// robot), one transaction per batch: $robots[i] was at ($xs[i], $ys[i], $zs[i]) at $stamps[i]
// (seconds since the Unix epoch, the sample's own time); $seqs[i] numbers it in storing order.
UNWIND range(0, size($stamps) - 1) AS i
CREATE (:LivePose {log: $log, seq: $seqs[i], robot: $robots[i], stamp: $stamps[i], x: $xs[i],
                   y: $ys[i], z: $zs[i]})
