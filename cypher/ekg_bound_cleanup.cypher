// Remove what the baseline of benchmarks/ekg_build.py wrote (ekg_bound_nodes, _edges).
// Batched: run it as an auto-commit query.
MATCH (n:BoundNode)
CALL (n) { DETACH DELETE n } IN TRANSACTIONS OF 10000 ROWS
