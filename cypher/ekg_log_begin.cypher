// The Log node of a log being built: its source, event properties, entity types and the
// run (write lock) that builds it. `status` becomes 'complete' once everything is written.
CREATE (l:Log {name: $log, status: 'building', run: $run, source: $source, created: datetime(),
               properties: $properties, entityTypes: $entityTypes})
