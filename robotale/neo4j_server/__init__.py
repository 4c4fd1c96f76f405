"""The local Neo4j server robotale starts for a user without one: the pinned jars and their
download, the Java that runs them, the server's configuration and its lifecycle (start, stop,
the lock that keeps one writer per home, the process holding a port).

It sits below the graph code: :mod:`robotale.ekg.connection` asks it for a running server
and knows nothing of how one is started.
"""
