// How many tags the live run $log holds so far (0 when there is no such run): a reader
// rebuilds its copy of the run only when this grew.
MATCH (t:LiveTag {log: $log})
RETURN count(t) AS tags
