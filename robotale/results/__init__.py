"""The prepared results of a stored log: what the dashboard shows and the command line also
computes (the discovered graphs, the findings, the perspectives and the timeline), kept beside
the log's columnar copy so a page or a command reads them instead of computing them again.

It sits below the webapp: ``robotale ingest`` prepares them through this part, and the
dashboard's views read them through it, so a log name followed from the command to Neo4j
never passes through the webapp.
"""
