"""The objects of an object-centric log in its EKG: attributes, qualifiers, REL edges.

The events and their Entity nodes are written as for any log (:mod:`robotale.ekg.build`, one
entity type per object type). :func:`write_objects` then adds what only an object-centric
log says: each object's attributes as properties of its Entity node (an object no event
relates to gets its node here), the qualifiers of each event's CORR edge to an object (a
list: OCEL lets one event relate to one object in several roles), and the object-to-object
relations as REL edges with their qualifier. The Entity keeps each attribute's value from the
beginning; each later change is an ``AttributeChange`` node (field, value, time) the Entity
has a CHANGED edge to.
"""

from __future__ import annotations

from typing import Any

import pandas as pd

from robotale.ekg.load import Loader, neo4j_values
from robotale.eventlog.objects import Objects


def write_objects(loader: Loader, objects: Objects, entity_types: list[str]) -> None:
    """Write the objects of ``entity_types`` (the others are no entities of this log)."""
    table = objects.objects.assign(type=objects.objects["type"].map(objects.column))
    table = table[table["type"].isin(entity_types)]
    for kind, part in table.groupby("type", sort=False):
        present = [c for c in objects.attributes if part[c].notna().any()]
        properties = {name: neo4j_values(part[name].reset_index(drop=True)) for name in present}
        loader.run(
            "ekg_object_entities",
            {"ids": part["id"].astype(str).tolist()},
            {"properties": properties},
            type=kind,
        )
    kinds = table.set_index("id")["type"]
    _write_qualifiers(loader, objects.e2o, kinds)
    _write_relations(loader, objects.o2o, kinds)
    _write_changes(loader, objects.changes, kinds)


def _write_qualifiers(loader: Loader, e2o: pd.DataFrame, kinds: pd.Series) -> None:
    named = e2o[e2o["qualifier"].notna() & e2o["object"].isin(kinds.index)]
    if named.empty:
        return
    grouped = named.groupby(["event", "object"], sort=False)["qualifier"].agg(
        lambda q: sorted(set(map(str, q)))
    )
    pairs = grouped.reset_index()
    loader.run(
        "ekg_object_qualifiers",
        {
            "events": pairs["event"].astype(str).tolist(),
            "types": pairs["object"].map(kinds).tolist(),
            "objects": pairs["object"].astype(str).tolist(),
            "qualifiers": pairs["qualifier"].tolist(),
        },
    )


def _write_relations(loader: Loader, o2o: pd.DataFrame, kinds: pd.Series) -> None:
    relations = o2o[o2o["source"].isin(kinds.index) & o2o["target"].isin(kinds.index)]
    if relations.empty:
        return
    loader.run("ekg_object_relations", relation_parameters(relations, kinds))


def relation_parameters(relations: pd.DataFrame, kinds: pd.Series) -> dict[str, list[Any]]:
    """The query columns of object-to-object relations between objects of ``kinds``."""
    qualifiers = relations["qualifier"].astype(object)
    return {
        "sources": relations["source"].astype(str).tolist(),
        "sourceTypes": relations["source"].map(kinds).tolist(),
        "targets": relations["target"].astype(str).tolist(),
        "targetTypes": relations["target"].map(kinds).tolist(),
        "qualifiers": qualifiers.where(qualifiers.notna(), None).tolist(),
    }


def _write_changes(loader: Loader, changes: pd.DataFrame, kinds: pd.Series) -> None:
    found = changes[changes["object"].isin(kinds.index)].reset_index(drop=True)
    if found.empty:
        return
    loader.run("ekg_object_changes", change_parameters(found, kinds))


def change_parameters(found: pd.DataFrame, kinds: pd.Series) -> dict[str, list[Any]]:
    """The query columns of attribute changes of objects of ``kinds``."""
    return {
        "objects": found["object"].astype(str).tolist(),
        "types": found["object"].map(kinds).tolist(),
        "fields": found["field"].astype(str).tolist(),
        "values": neo4j_values(found["value"].astype(object)),
        "times": neo4j_values(pd.to_datetime(found["time"], utc=True)),
    }
