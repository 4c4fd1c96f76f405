// Messages between the classes of type $type in log $log: the COMM edges (send event ->
// receive event) lifted to the classes of their events. A message counts once per pair of
// classes, however many start/complete events its send and receive have; its latency is
// from its first send event to its first receive event in that pair.
MATCH (a:Class {log: $log, type: $type})<-[:OBSERVED]-(s:Event)-[m:COMM]->(t:Event)
      -[:OBSERVED]->(b:Class {log: $log, type: $type})
WITH a, b, m.msgId AS message, min(s.timestamp) AS sent, min(t.timestamp) AS received
WITH a, b, message,
     (received.epochSeconds - sent.epochSeconds)
     + (received.nanosecond - sent.nanosecond) / 1e9 AS seconds
RETURN a.id AS source, b.id AS target, count(message) AS count,
       avg(seconds) AS meanSeconds, percentileCont(seconds, 0.5) AS medianSeconds
ORDER BY source, target
