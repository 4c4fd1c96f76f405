// The nodes a step collapses (element ids $members[i]) record the aggregate that holds them:
// its id $aggregates[i] in their property `_aggregate`. One property per node rather than an
// edge to the aggregate: Neo4j sets it faster than it links a node into a chain of edges
// (an aggregate may hold a million), and undo removes it without touching the aggregate.
// robotale's own property names start with a letter, so `_aggregate` is no log's column.
UNWIND range(0, size($members) - 1) AS i
MATCH (n) WHERE elementId(n) = $members[i]
SET n._aggregate = $aggregates[i]
