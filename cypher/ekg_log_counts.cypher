// What log $log holds, counted from the graph itself: one row per kind of node or edge and
// entity / class type.
CALL () {
  MATCH (e:Event) WHERE e.log = $log AND e.id IS NOT NULL
  RETURN 'events' AS what, null AS type, count(e) AS count
  UNION ALL
  MATCH (e:Event) WHERE e.log = $log AND e.id IS NOT NULL
  RETURN 'cases' AS what, null AS type, count(DISTINCT e.case) AS count
  UNION ALL
  MATCH (n:Entity) WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL
  RETURN 'entities' AS what, n.type AS type, count(n) AS count
  UNION ALL
  MATCH (n:Entity)<-[r:CORR]-(:Event)
  WHERE n.log = $log AND n.type IS NOT NULL AND n.id IS NOT NULL
  RETURN 'CORR' AS what, n.type AS type, count(r) AS count
  UNION ALL
  MATCH (e:Event)-[r:DF]->(:Event) WHERE e.log = $log AND e.id IS NOT NULL
  RETURN 'DF' AS what, r.entityType AS type, count(r) AS count
  UNION ALL
  MATCH (e:Event)-[r:COMM]->(:Event) WHERE e.log = $log AND e.id IS NOT NULL
  RETURN 'COMM' AS what, null AS type, count(r) AS count
  UNION ALL
  MATCH (c:Class) WHERE c.log = $log AND c.type IS NOT NULL AND c.id IS NOT NULL
  RETURN 'classes' AS what, c.type AS type, count(c) AS count
  UNION ALL
  MATCH (c:Class)<-[r:OBSERVED]-(:Event) WHERE c.log = $log AND c.type IS NOT NULL AND c.id IS NOT NULL
  RETURN 'OBSERVED' AS what, c.type AS type, count(r) AS count
  UNION ALL
  MATCH (c:Class)<-[r:BEGINS]-(:Entity) WHERE c.log = $log AND c.type IS NOT NULL AND c.id IS NOT NULL
  RETURN 'BEGINS' AS what, c.type AS type, count(r) AS count
  UNION ALL
  MATCH (c:Class)-[r:DF_C]->(:Class) WHERE c.log = $log AND c.type IS NOT NULL AND c.id IS NOT NULL
  RETURN 'DF_C' AS what, c.type + ' / ' + r.entityType AS type, count(r) AS count
}
RETURN what, type, count
