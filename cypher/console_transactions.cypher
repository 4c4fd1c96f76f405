// The transactions of one console request (their metadata names it), still on the server.
SHOW TRANSACTIONS YIELD transactionId, metaData, status, elapsedTime
WHERE metaData.robotale_console = $request
RETURN transactionId, status, elapsedTime
