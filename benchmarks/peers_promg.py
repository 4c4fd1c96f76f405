"""PromG's side of benchmarks/peers.py, run by the Python of the benchmark's own virtual
environment (where PromG is installed; robotale is not).

    python peers_promg.py SETTINGS.json

SETTINGS names the Neo4j (uri, user, password), PromG's semantic header and dataset
description, the entity types to aggregate and the batch size. Run from the folder the dataset
description's ``file_directory`` is relative to. Writes PromG's version and the seconds of the
build (constraints, records, events, entities, CORR, DF, classes, DF_A) as JSON to the file
SETTINGS names as ``result``.
"""

from __future__ import annotations

import json
import sys
import time
from importlib.metadata import version


def main() -> int:
    with open(sys.argv[1], encoding="utf-8") as stream:
        settings = json.load(stream)
    from promg import (
        Configuration,
        DatabaseConnection,
        DatasetDescriptions,
        OcedPg,
        Performance,
        SemanticHeader,
    )
    from promg.modules.db_management import DBManagement
    from promg.modules.process_discovery import ProcessDiscovery

    # PromG's step tracker is a singleton; made first here, it writes no progress bar around
    # our timing and hides nothing of stdout.
    Performance(perf_path=None, write_console=False)
    config = Configuration(
        semantic_header_path=settings["semantic_header"],
        dataset_description_path=settings["dataset_description"],
        db_name="neo4j",
        uri=settings["uri"],
        user=settings["user"],
        password=settings["password"],
        verbose=False,
        batch_size=settings["batch_size"],
        use_sample=False,
        use_preprocessed_files=False,
    )
    connection = DatabaseConnection(
        uri=config.uri,
        db_name=config.db_name,
        user=config.user,
        password=config.password,
        batch_size=config.batch_size,
    )
    header = SemanticHeader.create_semantic_header(config=config)
    descriptions = DatasetDescriptions(config=config)
    started = time.perf_counter()
    DBManagement(db_connection=connection, semantic_header=header).set_constraints()
    builder = OcedPg(
        database_connection=connection,
        dataset_descriptions=descriptions,
        semantic_header=header,
        store_files=False,
    )
    builder.load_and_transform()
    builder.create_df_edges()
    discovery = ProcessDiscovery(db_connection=connection)
    for entity_type in settings["aggregate_entities"]:
        # PromG 2.4.7's create_df_process_model asks SemanticHeader() for the header, which
        # fails (it is no singleton); its worker takes the entity from our header instead.
        discovery._create_df_process_model(entity=header.get_entity(entity_type))
    seconds = time.perf_counter() - started
    # A file, not stdout: PromG's progress bar writes there.
    with open(settings["result"], "w", encoding="utf-8") as stream:
        json.dump({"promg": version("promg"), "seconds": seconds}, stream)
    return 0


if __name__ == "__main__":
    sys.exit(main())
