// The server's client connections other than those whose user agent is $agent (the asking
// process's own): who else is connected, e.g. before the server is stopped for an import.
CALL dbms.listConnections() YIELD connectionId, connector, userAgent, clientAddress
WITH * WHERE userAgent IS NULL OR userAgent <> $agent
RETURN connectionId, connector, userAgent, clientAddress
