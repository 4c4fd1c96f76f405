// One batch of the aggregates of step $step of log $log: $ids, $names, $counts (how many
// nodes each replaces), $origin ('Event' or 'Entity'), $type (the entity type, or null),
// $key (the group-by names) and $properties {key: [values]} (group-by values and attribute
// aggregations; null values are not stored). Returns [row, element id] pairs. The step's
// record (as aggr_step_begin writes it: $spec, $run) comes with its first batch, in the same
// transaction: one write fewer per step. So do the member lists of the batch's aggregates
// when they are short ($memberOf[j]: an aggregate id, $parts[j], $members[j], as
// aggr_create_members writes them; empty lists when they go apart): a round trip fewer.
MERGE (s:AggregationStep {log: $log, step: $step})
ON CREATE SET s.spec = $spec, s.status = 'writing', s.created = datetime(), s.run = $run
WITH s
UNWIND range(0, size($ids) - 1) AS i
CREATE (a:Aggregate {log: $log, step: $step, id: $ids[i], name: $names[i], count: $counts[i],
                     origin: $origin, key: $key})
SET a.type = $type
FOREACH (key IN keys($properties) | SET a[key] = $properties[key][i])
WITH collect([i, elementId(a)]) AS nodes
FOREACH (j IN range(0, size($memberOf) - 1) |
  CREATE (:AggregateMembers {log: $log, step: $step, id: $memberOf[j], part: $parts[j],
                             members: $members[j]}))
RETURN nodes
