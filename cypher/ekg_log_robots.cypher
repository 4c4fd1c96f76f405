// The robots of log $log (the Model page finds the collaboration whose pools bind them): as
// the Log node records them, else the distinct robot property of its events.
OPTIONAL MATCH (l:Log {name: $log})
OPTIONAL CALL (l) {
  WITH l WHERE l IS NULL OR l.robots IS NULL
  MATCH (e:Event {log: $log})
  WHERE e.robot IS NOT NULL
  RETURN collect(DISTINCT e.robot) AS robots
}
RETURN coalesce(l.robots, robots) AS robots
