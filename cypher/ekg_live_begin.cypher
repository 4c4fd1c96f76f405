// The Log node of a live log (one a monitor grows while its run goes on): status 'live' until
// the run ends, its source $source, event properties, entity and class types, and the run
// (write lock) that grows it.
CREATE (l:Log {name: $log, status: $status, run: $run, source: $source, created: datetime(),
               properties: $properties, entityTypes: $entityTypes, classTypes: $classTypes})
