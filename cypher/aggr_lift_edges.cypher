// The relationships of the nodes the aggregates $aggregates (element ids, all of step $step)
// replace, lifted to them: every CORR, DF and COMM edge of a member becomes an edge of the
// same type between the aggregate and what now stands for its other end at this level (the
// aggregate holding that node, else the node), one per pair (and entity type, for DF) with
// `count`, the number of edges it stands for, and `step`. An edge between two aggregates of
// this step is written once, from its source's side. Only edges between events and entities
// are lifted: those the build wrote, never those of earlier steps.
UNWIND $aggregates AS aggregate
MATCH (a:Aggregate) WHERE elementId(a) = aggregate
CALL (a) {
  MATCH (a)<-[:AGGREGATED_IN]-(:Event)-[:CORR]->(o:Entity)
  OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
  WITH coalesce(g, o) AS other, count(*) AS count
  CREATE (a)-[:CORR {step: $step, count: count}]->(other)
}
CALL (a) {
  MATCH (a)<-[:AGGREGATED_IN]-(:Entity)<-[:CORR]-(o:Event)
  OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
  WITH coalesce(g, o) AS other, count(*) AS count
  CREATE (other)-[:CORR {step: $step, count: count}]->(a)
}
CALL (a) {
  MATCH (a)<-[:AGGREGATED_IN]-(:Event)-[r:DF]->(o:Event)
  OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
  WITH coalesce(g, o) AS other, r.entityType AS entityType, count(*) AS count
  CREATE (a)-[:DF {step: $step, entityType: entityType, count: count}]->(other)
}
CALL (a) {
  MATCH (a)<-[:AGGREGATED_IN]-(:Event)<-[r:DF]-(o:Event)
  OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
  WITH g, o, r WHERE g IS NULL OR g.step <> $step
  WITH coalesce(g, o) AS other, r.entityType AS entityType, count(*) AS count
  CREATE (other)-[:DF {step: $step, entityType: entityType, count: count}]->(a)
}
CALL (a) {
  MATCH (a)<-[:AGGREGATED_IN]-(:Event)-[:COMM]->(o:Event)
  OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
  WITH coalesce(g, o) AS other, count(*) AS count
  CREATE (a)-[:COMM {step: $step, count: count}]->(other)
}
CALL (a) {
  MATCH (a)<-[:AGGREGATED_IN]-(:Event)<-[:COMM]-(o:Event)
  OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
  WITH g, o WHERE g IS NULL OR g.step <> $step
  WITH coalesce(g, o) AS other, count(*) AS count
  CREATE (other)-[:COMM {step: $step, count: count}]->(a)
}
RETURN count(*) AS aggregates
