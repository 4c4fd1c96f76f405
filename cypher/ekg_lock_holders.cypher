// Every write lock: which log it guards and who holds it.
MATCH (k:LogLock)
RETURN k.name AS name, k.run AS run, k.host AS host, k.pid AS pid, k.pidStart AS pidStart,
       toString(k.started) AS started
