// How many nodes carry each label and how many relationships have each type, read from
// Neo4j's count store (no scan): benchmarks/peers.py and whole_ingest.py compare two
// builders' graphs between timed runs, where a scan of every relationship per type would
// take minutes at a million events.
CALL db.stats.retrieve('GRAPH COUNTS') YIELD data
UNWIND data.nodes AS node
WITH data, node WHERE node.label IS NOT NULL
RETURN 'node' AS kind, node.label AS name, node.count AS count
UNION ALL
CALL db.stats.retrieve('GRAPH COUNTS') YIELD data
UNWIND data.relationships AS relationship
WITH relationship
WHERE relationship.relationshipType IS NOT NULL
  AND relationship.startLabel IS NULL AND relationship.endLabel IS NULL
RETURN 'relationship' AS kind, relationship.relationshipType AS name, relationship.count AS count
