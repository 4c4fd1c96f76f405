// Baseline for benchmarks/aggregate.py: Neo4j's own rate of writing a step's lifted edges.
// One batch of relationships between the ends of lifted edges (element ids $sources[i] ->
// $targets[i]), each with the properties a lifted CORR edge has ($step, $counts[i]), and
// nothing else: no kind chosen, no key looked up. Each touches an aggregate, so robotale's
// undo of the step removes them with it.
UNWIND range(0, size($sources) - 1) AS i
MATCH (a) WHERE elementId(a) = $sources[i]
MATCH (b) WHERE elementId(b) = $targets[i]
CREATE (a)-[:BOUND {step: $step, count: $counts[i]}]->(b)
