// How many tags and odometry samples the live run $log holds so far (0 when there is no such
// run). They are numbered 1, 2, ... as stored by the run's one writer, so the count is the
// last number: one seek at the end of each (log, seq) index (two db hits), where counting
// read every entry, and scanned every node of the label, at each look of a reader that counts
// (120,000 samples after ten minutes of 20 robots). The order names both of the index's
// properties, as Neo4j needs to read a composite index backwards instead of sorting.
CALL () {
  MATCH (t:LiveTag {log: $log})
  WHERE t.seq IS NOT NULL
  WITH t ORDER BY t.log DESC, t.seq DESC LIMIT 1
  RETURN collect(t.seq) AS tags
}
CALL () {
  MATCH (p:LivePose {log: $log})
  WHERE p.seq IS NOT NULL
  WITH p ORDER BY p.log DESC, p.seq DESC LIMIT 1
  RETURN collect(p.seq) AS poses
}
RETURN coalesce(tags[0], 0) AS tags, coalesce(poses[0], 0) AS poses
