"""Packaging details pyproject.toml cannot express: ``cypher/`` at the repository root is
installed as the package ``robotale.cypher``, so the queries are files a user opens in Neo4j
Browser and, in an installed robotale, package data found with importlib.resources."""

from setuptools import find_packages, setup

setup(
    packages=[*find_packages(include=["robotale*"]), "robotale.cypher"],
    package_dir={"robotale.cypher": "cypher"},
)
