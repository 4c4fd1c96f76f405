// How many of the constraints an aggregation relies on ($names) the database has: when all,
// the schema of cypher/ekg_schema.cypher need not be asked for again (ten statements).
SHOW CONSTRAINTS YIELD name
WHERE name IN $names
RETURN count(*) AS present
