// Who holds the write lock of log $name (no row when nobody does).
MATCH (k:LogLock {name: $name})
RETURN k.run AS run, k.host AS host, k.pid AS pid, k.pidStart AS pidStart,
       toString(k.started) AS started
