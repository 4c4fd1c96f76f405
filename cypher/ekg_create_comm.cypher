// COMM edges from a send event to a receive event of the same message (node ids).
UNWIND range(0, size($sources) - 1) AS i
MATCH (a) WHERE id(a) = $sources[i]
MATCH (b) WHERE id(b) = $targets[i]
CREATE (a)-[:COMM {msgId: $msgIds[i]}]->(b)
