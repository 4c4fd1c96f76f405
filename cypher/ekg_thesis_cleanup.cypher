// Remove what the thesis baseline of benchmarks/ekg_build.py wrote: its events carry `Log`,
// its entities no `log`. Batched: run it as an auto-commit query.
MATCH (n)
WHERE (n:Event AND n.Log IS NOT NULL) OR (n:Entity AND n.log IS NULL)
CALL (n) { DETACH DELETE n } IN TRANSACTIONS OF 10000 ROWS
