// How many entities log $log has, aggregated or not: with the members of its aggregation steps,
// OCEAN's verification counts (the events are counted in the log's event table).
MATCH (n:Entity)
WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL
RETURN count(n) AS entities
