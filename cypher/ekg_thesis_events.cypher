// Baseline for benchmarks/ekg_build.py: the thesis' event loading (section 7.1.2,
// `LOAD CSV ... CREATE (e:Event {Log: ..., ...})`, one node per line), the lines given as $rows.
UNWIND $rows AS line
CREATE (e:Event {Log: $log})
SET e += line
