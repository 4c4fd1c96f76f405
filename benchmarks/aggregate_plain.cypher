// The logistics specification of benchmarks/aggregate.py written as plain Cypher, the way the
// field writes aggregation steps (one MATCH ... CREATE per step; then, as OCEAN relates its
// classes once after its steps, one query per step and kind of lifted edge), writing the same
// Aggregate nodes and edges robotale writes. Statements in order; each names its step in its
// first comment line. Parameters: $log, $cutoff. The edges (AGGREGATED_IN, lifted) are
// created in batches (CALL ... IN TRANSACTIONS, as the field writes large updates): in one
// transaction each, a million events pass the server's limit on a transaction's memory. Run
// them as auto-commit queries. A step's aggregates are created one per transaction with their
// members' edges (Neo4j takes no CALL ... IN TRANSACTIONS after a write).

// step 1: containers by Status; id MULTISET, Weight AVG, Amount_of_Handling_Units MINMAX
MATCH (n:Entity {log: $log, type: 'Container'}) WHERE NOT (n)-[:AGGREGATED_IN]->()
WITH n.Status AS key, collect(n) AS nodes, avg(n.Weight) AS weight,
     min(n.Amount_of_Handling_Units) AS low, max(n.Amount_of_Handling_Units) AS high
CALL (nodes) {
  UNWIND nodes AS n
  WITH toString(n.id) AS value, count(*) AS times ORDER BY value
  RETURN collect(value + ':' + toString(times)) AS ids
}
WITH key, nodes, weight, low, high, ids, coalesce(toString(key), 'unknown') AS name
CALL (key, nodes, weight, low, high, ids, name) {
  CREATE (a:Aggregate {log: $log, step: 1, id: '1:' + name, name: name, count: size(nodes),
                       origin: 'Entity', type: 'Container', key: ['Status'], Status: key,
                       id_multiset: ids, Weight_avg: weight,
                       Amount_of_Handling_Units_min: low, Amount_of_Handling_Units_max: high})
  FOREACH (n IN nodes | CREATE (n)-[:AGGREGATED_IN]->(a))
} IN TRANSACTIONS OF 1 ROWS;

// step 2: customer orders of 1000 goods or more by Type; Amount_of_Goods SUM
MATCH (n:Entity {log: $log, type: 'Customer_Order'})
WHERE NOT (n)-[:AGGREGATED_IN]->() AND n.Amount_of_Goods >= 1000
WITH n.Type AS key, collect(n) AS nodes, sum(n.Amount_of_Goods) AS goods
WITH key, nodes, goods, coalesce(toString(key), 'unknown') AS name
CALL (key, nodes, goods, name) {
  CREATE (a:Aggregate {log: $log, step: 2, id: '2:' + name, name: name, count: size(nodes),
                       origin: 'Entity', type: 'Customer_Order', key: ['Type'], Type: key,
                       Amount_of_Goods_sum: goods})
  FOREACH (n IN nodes | CREATE (n)-[:AGGREGATED_IN]->(a))
} IN TRANSACTIONS OF 1 ROWS;

// step 3: the other customer orders by Type; Amount_of_Goods MIN and MAX
MATCH (n:Entity {log: $log, type: 'Customer_Order'})
WHERE NOT (n)-[:AGGREGATED_IN]->() AND n.Amount_of_Goods < 1000
WITH n.Type AS key, collect(n) AS nodes, min(n.Amount_of_Goods) AS low,
     max(n.Amount_of_Goods) AS high
WITH key, nodes, low, high, coalesce(toString(key), 'unknown') AS name
CALL (key, nodes, low, high, name) {
  CREATE (a:Aggregate {log: $log, step: 3, id: '3:' + name, name: name, count: size(nodes),
                       origin: 'Entity', type: 'Customer_Order', key: ['Type'], Type: key,
                       Amount_of_Goods_min: low, Amount_of_Goods_max: high})
  FOREACH (n IN nodes | CREATE (n)-[:AGGREGATED_IN]->(a))
} IN TRANSACTIONS OF 1 ROWS;

// step 4: events up to $cutoff by activity and the aggregates of their orders; time MINMAX
MATCH (n:Event {log: $log})
WHERE NOT (n)-[:AGGREGATED_IN]->() AND n.timestamp <= $cutoff
CALL (n) {
  OPTIONAL MATCH (n)-[:CORR]->(x:Entity {type: 'Customer_Order'})
  OPTIONAL MATCH (x)-[:AGGREGATED_IN]->(g:Aggregate)
  WITH DISTINCT coalesce(g.id, x.id) AS value
  WHERE value IS NOT NULL
  WITH value ORDER BY value
  RETURN collect(value) AS values
}
WITH n, CASE WHEN size(values) = 0 THEN null
             ELSE reduce(s = head(values), v IN tail(values) | s + ',' + v) END AS orders
WITH n.activity AS activity, orders, collect(n) AS nodes, min(n.timestamp) AS first,
     max(n.timestamp) AS last
WITH activity, orders, nodes, first, last,
     coalesce(activity, 'unknown') + '|' + coalesce(orders, 'unknown') AS name
CALL (activity, orders, nodes, first, last, name) {
  CREATE (a:Aggregate {log: $log, step: 4, id: '4:' + name, name: name, count: size(nodes),
                       origin: 'Event', key: ['activity', 'Customer_Order'], activity: activity,
                       Customer_Order: orders, timestamp_min: first, timestamp_max: last})
  FOREACH (n IN nodes | CREATE (n)-[:AGGREGATED_IN]->(a))
} IN TRANSACTIONS OF 1 ROWS;

// step 5: the later events by activity; time MIN
MATCH (n:Event {log: $log})
WHERE NOT (n)-[:AGGREGATED_IN]->() AND n.timestamp > $cutoff
WITH n.activity AS activity, collect(n) AS nodes, min(n.timestamp) AS first
WITH activity, nodes, first, coalesce(activity, 'unknown') AS name
CALL (activity, nodes, first, name) {
  CREATE (a:Aggregate {log: $log, step: 5, id: '5:' + name, name: name, count: size(nodes),
                       origin: 'Event', key: ['activity'], activity: activity,
                       timestamp_min: first})
  FOREACH (n IN nodes | CREATE (n)-[:AGGREGATED_IN]->(a))
} IN TRANSACTIONS OF 1 ROWS;

// lift: CORR from the events of the aggregates of step $step, to what stands for the entity
// after the last step (its aggregate, else itself) when that is of step $step or earlier (an
// edge to an aggregate of a later step is that step's)
MATCH (a:Aggregate {log: $log, step: $step})<-[:AGGREGATED_IN]-(:Event)-[:CORR]->(o:Entity)
OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
WITH a, o, g WHERE g IS NULL OR g.step <= $step
WITH a, coalesce(g, o) AS other, count(*) AS count
CALL (a, other, count) {
  CREATE (a)-[:CORR {step: $step, count: count}]->(other)
} IN TRANSACTIONS OF 10000 ROWS;

// lift: CORR to the entities of the aggregates of step $step, from events of earlier steps'
// aggregates or of none
MATCH (a:Aggregate {log: $log, step: $step})<-[:AGGREGATED_IN]-(:Entity)<-[:CORR]-(o:Event)
OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
WITH a, o, g WHERE g IS NULL OR g.step < $step
WITH a, coalesce(g, o) AS other, count(*) AS count
CALL (a, other, count) {
  CREATE (other)-[:CORR {step: $step, count: count}]->(a)
} IN TRANSACTIONS OF 10000 ROWS;

// lift: DF from the events of the aggregates of step $step, to events of aggregates of this
// step or earlier ones or of none
MATCH (a:Aggregate {log: $log, step: $step})<-[:AGGREGATED_IN]-(:Event)-[r:DF]->(o:Event)
OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
WITH a, o, g, r WHERE g IS NULL OR g.step <= $step
WITH a, coalesce(g, o) AS other, r.entityType AS entityType, count(*) AS count
CALL (a, other, entityType, count) {
  CREATE (a)-[:DF {step: $step, entityType: entityType, count: count}]->(other)
} IN TRANSACTIONS OF 10000 ROWS;

// lift: DF to the events of the aggregates of step $step from events of earlier steps'
// aggregates or of none
MATCH (a:Aggregate {log: $log, step: $step})<-[:AGGREGATED_IN]-(:Event)<-[r:DF]-(o:Event)
OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
WITH a, g, o, r WHERE g IS NULL OR g.step < $step
WITH a, coalesce(g, o) AS other, r.entityType AS entityType, count(*) AS count
CALL (a, other, entityType, count) {
  CREATE (other)-[:DF {step: $step, entityType: entityType, count: count}]->(a)
} IN TRANSACTIONS OF 10000 ROWS;

// lift: COMM from the events of the aggregates of step $step, to events of aggregates of this
// step or earlier ones or of none
MATCH (a:Aggregate {log: $log, step: $step})<-[:AGGREGATED_IN]-(:Event)-[:COMM]->(o:Event)
OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
WITH a, o, g WHERE g IS NULL OR g.step <= $step
WITH a, coalesce(g, o) AS other, count(*) AS count
CALL (a, other, count) {
  CREATE (a)-[:COMM {step: $step, count: count}]->(other)
} IN TRANSACTIONS OF 10000 ROWS;

// lift: COMM to the events of the aggregates of step $step from events of earlier steps'
// aggregates or of none
MATCH (a:Aggregate {log: $log, step: $step})<-[:AGGREGATED_IN]-(:Event)<-[:COMM]-(o:Event)
OPTIONAL MATCH (o)-[:AGGREGATED_IN]->(g:Aggregate)
WITH a, g, o WHERE g IS NULL OR g.step < $step
WITH a, coalesce(g, o) AS other, count(*) AS count
CALL (a, other, count) {
  CREATE (other)-[:COMM {step: $step, count: count}]->(a)
} IN TRANSACTIONS OF 10000 ROWS;

// output: every aggregate of log $log
MATCH (a:Aggregate {log: $log}) RETURN properties(a) AS a, elementId(a) AS element;

// output: every lifted edge out of the aggregate with element id $aggregate (read one
// aggregate at a time: at a million events all of them at once pass the server's limit on a
// transaction's memory)
MATCH (a)-[r:CORR|DF|COMM]->(b)
WHERE elementId(a) = $aggregate AND r.step IS NOT NULL
RETURN a.id AS source, b.id AS target, type(r) AS type, r.entityType AS entityType,
       r.count AS count, r.step AS step;

// output: every lifted edge into the aggregate with element id $aggregate from a node that is
// no aggregate of log $log (those are read as edges out of their aggregate)
MATCH (b)-[r:CORR|DF|COMM]->(a)
WHERE elementId(a) = $aggregate AND r.step IS NOT NULL AND NOT (b:Aggregate AND b.log = $log)
RETURN b.id AS source, a.id AS target, type(r) AS type, r.entityType AS entityType,
       r.count AS count, r.step AS step;

// attributes: the rows $rows (id and attributes) set on the entities of type $type
UNWIND $rows AS row
MATCH (n:Entity {log: $log, type: $type, id: row.id})
SET n += row;

// ends: the element ids of the ends of every lifted edge out of the aggregate with element id
// $aggregate, and of those into it from a node that is no aggregate of log $log
CALL () {
  MATCH (a)-[r:CORR|DF|COMM]->(b)
  WHERE elementId(a) = $aggregate AND r.step IS NOT NULL
  RETURN a, b
  UNION ALL
  MATCH (b)-[r:CORR|DF|COMM]->(a)
  WHERE elementId(a) = $aggregate AND r.step IS NOT NULL AND NOT (b:Aggregate AND b.log = $log)
  RETURN b AS a, a AS b
}
RETURN elementId(a) AS source, elementId(b) AS target;

// running: the transactions of the log's database but this one (those of a run the benchmark
// stopped: Neo4j goes on with a query whose client went away)
SHOW TRANSACTIONS YIELD transactionId, currentQuery
WHERE NOT currentQuery CONTAINS 'SHOW TRANSACTIONS'
RETURN transactionId;

// terminate: the transactions $ids
TERMINATE TRANSACTIONS $ids;
