// DF edges of the entities ($types[i], $ids[i]) of log $log over all their events, stored and
// appended: consecutive events of an entity in one case, in the order of their times, then of
// their positions in the log (as robotale.ekg.tables orders a new log's chains).
UNWIND range(0, size($ids) - 1) AS i
MATCH (n:Entity {log: $log, type: $types[i], id: $ids[i]})<-[:CORR]-(e:Event)
WHERE e.case IS NOT NULL
WITH n, e ORDER BY e.timestamp, e.order
WITH n, e.case AS case, collect(e) AS chain
UNWIND range(1, size(chain) - 1) AS j
WITH n, chain[j - 1] AS a, chain[j] AS b
CREATE (a)-[:DF {entityType: n.type, entityId: n.id}]->(b)
