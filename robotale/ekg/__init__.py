"""Event Knowledge Graph in Neo4j: the local server, the connection, the schema, loading,
and aggregation into Class graphs. Every query is a file in ``cypher/``."""
