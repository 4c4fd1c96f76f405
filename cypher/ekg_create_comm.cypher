// COMM edges from a send event to a receive event of the same message (element ids).
UNWIND range(0, size($sources) - 1) AS i
MATCH (a) WHERE elementId(a) = $sources[i]
MATCH (b) WHERE elementId(b) = $targets[i]
CREATE (a)-[:COMM {msgId: $msgIds[i]}]->(b)
