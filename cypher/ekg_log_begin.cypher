// The Log node of a log being built: its source, event properties and entity types.
// `status` becomes 'complete' once everything is written.
CREATE (l:Log {name: $log, status: 'building', source: $source, created: datetime(),
               properties: $properties, entityTypes: $entityTypes})
