// Baseline for benchmarks/ekg_build.py: the thesis' DF query (section 7.1.2): collect each
// entity's events by time, MERGE an edge between neighbours. The thesis writes `n.entity_id`,
// a property its entities do not have (MERGE refuses null values): `n.id` is what it means.
MATCH (e:Event)-[:CORR]->(n:Entity)
WHERE n.type = $entitytype
WITH n, e AS event_nodes ORDER BY e.time
WITH n, collect(event_nodes) AS event_list
UNWIND range(0, size(event_list)-2) AS i
WITH n, event_list[i] AS e1, event_list[i+1] AS e2
MERGE (e1)-[df:DF {type:$entitytype,
                  id:n.id,
                  weight: 1}
      ]->(e2)
