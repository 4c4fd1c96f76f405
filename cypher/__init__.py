"""Every Cypher query robotale runs, one ``.cypher`` file each, installed as ``robotale.cypher``.

Open them in Neo4j Browser or a notebook: parameters are ``$names``, never pasted values.
"""
