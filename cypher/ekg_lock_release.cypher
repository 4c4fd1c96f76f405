// Give back the write lock of log $name, but only if run $run still holds it (a lock taken
// over from a writer that died belongs to the new writer).
MATCH (k:LogLock {name: $name, run: $run})
DELETE k
