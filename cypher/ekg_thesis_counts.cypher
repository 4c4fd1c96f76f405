// What the thesis baseline of benchmarks/ekg_build.py wrote, counted (its events carry `Log`,
// its entities no `log`): benchmarks/ekg_build.py checks robotale built as many events,
// entities, CORR and DF edges. A scan: the baseline runs at up to 100,000 events.
MATCH (e:Event) WHERE e.Log IS NOT NULL
WITH count(e) AS events
OPTIONAL MATCH (n:Entity) WHERE n.log IS NULL
WITH events, count(n) AS entities
OPTIONAL MATCH (:Event)-[c:CORR]->(n:Entity) WHERE n.log IS NULL
WITH events, entities, count(c) AS corr
OPTIONAL MATCH (a:Event)-[d:DF]->(:Event) WHERE a.Log IS NOT NULL
RETURN events, entities, corr, count(d) AS df
