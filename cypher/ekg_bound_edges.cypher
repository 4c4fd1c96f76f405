// Baseline for benchmarks/ekg_build.py: one batch of relationships without properties
// between nodes of ekg_bound_nodes (element ids $sources[i] -> $targets[i]).
UNWIND range(0, size($sources) - 1) AS i
MATCH (a) WHERE elementId(a) = $sources[i]
MATCH (b) WHERE elementId(b) = $targets[i]
CREATE (a)-[:BOUND]->(b)
