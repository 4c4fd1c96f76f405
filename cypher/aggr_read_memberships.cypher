// Which aggregate of log $log holds each node that earlier steps collapsed, so a step stacked
// on them leaves those nodes alone and lifts its edges to those aggregates: per aggregate, its
// id, step, element id, entity type (null for an aggregate of events) and the ids of its
// members.
MATCH (a:Aggregate)
WHERE a.log = $log AND a.id IS NOT NULL
OPTIONAL MATCH (m:AggregateMembers)
WHERE m.log = $log AND m.step = a.step AND m.id = a.id
WITH a, m ORDER BY m.part
RETURN a.id AS id, a.step AS step, elementId(a) AS aggregate, a.type AS type,
       reduce(all = [], part IN collect(m.members) | all + part) AS members
