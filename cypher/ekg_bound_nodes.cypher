// Baseline for benchmarks/ekg_build.py: Neo4j's own write rate. One batch of size($rows)
// nodes, each with the same $properties (as many as an event has), and nothing else: no
// index, no constraint, no computed value. Returns [row, element id] pairs as events do.
UNWIND range(0, size($rows) - 1) AS i
CREATE (n:BoundNode)
SET n += $properties
RETURN collect([i, elementId(n)]) AS nodes
