// Record on the Log node of $log, built by the run $run, the column types of the event table
// it was built from ($columns: an Arrow schema), so a columnar copy read back from the graph
// gets them again. Nothing is set if the log was rebuilt by another run meanwhile.
MATCH (l:Log {name: $log, run: $run})
SET l.columns = $columns
