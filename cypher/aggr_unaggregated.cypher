// How many events and entities of log $log no aggregate holds: OCEAN's verification counts.
CALL () {
  MATCH (n:Event)
  WHERE n.log = $log AND n.id IS NOT NULL AND n._aggregate IS NULL
  RETURN count(n) AS events
}
CALL () {
  MATCH (n:Entity)
  WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL AND n._aggregate IS NULL
  RETURN count(n) AS entities
}
RETURN events, entities
