// Wait until every index and constraint is online (populated), at most $seconds seconds.
CALL db.awaitIndexes($seconds)
