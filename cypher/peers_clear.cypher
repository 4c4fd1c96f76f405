// Empty the database between the builds of benchmarks/peers.py (its own private server).
// Batched: run it as an auto-commit query.
MATCH (n)
CALL (n) { DETACH DELETE n } IN TRANSACTIONS OF 10000 ROWS
