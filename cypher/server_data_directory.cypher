// The folder the server keeps its databases and transaction logs in (its setting), for the
// free-space check before a log is stored.
SHOW SETTINGS YIELD name, value
WHERE name = 'server.directories.data'
RETURN value AS folder
