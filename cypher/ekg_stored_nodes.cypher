// How many nodes the database holds besides the write lock of run $run (all when $run is
// null): a database with none has no graph yet.
MATCH (n)
WHERE $run IS NULL OR NOT n:LogLock OR n.run <> $run
RETURN count(n) AS nodes
