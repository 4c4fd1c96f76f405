// Take the write lock of log $name for one run of robotale (one writer per log name): the
// uniqueness constraint on LogLock.name refuses a second lock while this one exists. Run in a
// transaction of its own, before anything of the log is written. $host, $pid and $pidStart
// say who holds it, so a lock left by a writer that died can be recognised as such.
CREATE (k:LogLock {name: $name, run: $run, host: $host, pid: $pid, pidStart: $pidStart,
                   started: datetime()})
