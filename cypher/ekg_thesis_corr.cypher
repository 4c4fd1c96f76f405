// Baseline for benchmarks/ekg_build.py: the thesis' entity and CORR query (section 7.1.2),
// verbatim: a MERGE per event and entity.
MATCH (e:Event)
UNWIND e[$entitytype] AS ent_name
WITH DISTINCT ent_name, e
MERGE (n:Entity {id: ent_name, type: $entitytype})
MERGE (e)-[c:CORR]->(n)
