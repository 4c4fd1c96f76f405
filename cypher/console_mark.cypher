// Nothing: the read transaction around it is committed for its bookmark, which names the
// database's last committed transaction (the console's kept answers are valid until it changes).
RETURN 1 AS mark
