// Empty the database between the builds of benchmarks/peers.py (its own private server).
// Batched: run it as an auto-commit query. The relationships go first, in batches of their
// own: a node's DETACH DELETE holds all of its relationships in one transaction, and a
// Class or Log node of a million-event graph has hundreds of thousands of them, more than
// the stock server's transaction memory allows.
MATCH ()-[r]->()
CALL (r) { DELETE r } IN TRANSACTIONS OF 50000 ROWS
WITH count(*) AS relationships
MATCH (n)
CALL (n) { DELETE n } IN TRANSACTIONS OF 50000 ROWS
