// The names of Neo4j's built-in functions: the console allows these (and no plugin's).
SHOW FUNCTIONS YIELD name, isBuiltIn WHERE isBuiltIn RETURN name
