"""The objects of an object-centric log, kept next to its events.

An object-centric log (OCEL 2.0, or an OCED-style CSV with object tables) relates each event
to any number of objects, and objects to each other. The events become the canonical event
log of :mod:`.schema` with one column per object type listing the ids of the event's objects
of that type (comma-separated, as robotale's entity columns are); what the log says beyond
that travels in :class:`Objects`: each object's type and attributes, the qualifier of every
event-to-object relation, the object-to-object relations and the attribute changes over time.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog import schema

#: how an entity column lists several objects
SEPARATOR = ","
#: properties an Entity node keeps for itself: no object attribute may have these names
ENTITY_KEYS = ("log", "type", "id")
#: properties the graph sets on every Event node itself (robotale.ekg.tables.RESERVED, which
#: comes later in the data flow; a test keeps the two equal)
EVENT_OWN = ("log", "order")
#: what an object type's entity column is called when the events already use its name
COLUMN_PREFIX = "object:"
#: the columns of each table of :class:`Objects`
OBJECT_COLUMNS = ("type", "id")
E2O_COLUMNS = ("event", "object", "qualifier")
O2O_COLUMNS = ("source", "target", "qualifier")
CHANGE_COLUMNS = ("object", "time", "field", "value")


def _empty(columns: tuple[str, ...]) -> pd.DataFrame:
    return pd.DataFrame({name: pd.Series(dtype=object) for name in columns})


@dataclass(frozen=True)
class Objects:
    """What an object-centric log says about its objects."""

    #: ``type``, ``id`` and one column per attribute (its value from the beginning)
    objects: pd.DataFrame
    #: ``event`` (event id), ``object`` (object id), ``qualifier`` (None where there is none)
    e2o: pd.DataFrame = field(default_factory=lambda: _empty(E2O_COLUMNS))
    #: ``source``, ``target`` (object ids), ``qualifier``
    o2o: pd.DataFrame = field(default_factory=lambda: _empty(O2O_COLUMNS))
    #: ``object``, ``time``, ``field``, ``value``: an attribute's later values
    changes: pd.DataFrame = field(default_factory=lambda: _empty(CHANGE_COLUMNS))
    #: object type -> the log's column (entity type) of its objects, where the two differ
    columns: dict[str, str] = field(default_factory=dict)

    @property
    def types(self) -> list[str]:
        """The object types, in the order the log first names them."""
        return list(pd.unique(self.objects["type"].astype(str)))

    def column(self, kind: str) -> str:
        """The entity column (and entity type) of the object type ``kind``."""
        return self.columns.get(kind, kind)

    @property
    def entity_types(self) -> list[str]:
        return [self.column(kind) for kind in self.types]

    @property
    def attributes(self) -> list[str]:
        return [c for c in self.objects.columns if c not in OBJECT_COLUMNS]


@dataclass(frozen=True)
class ObjectLog:
    """An object-centric log as read: its events (``ocel:eid``, ``ocel:activity``,
    ``ocel:timestamp`` in UTC and one column per event attribute) and its :class:`Objects`."""

    events: pd.DataFrame
    objects: Objects


def entity_columns(source: Path, types: list[str], event_columns: list[str]) -> dict[str, str]:
    """Each object type becomes an entity column of the log, named as the type unless the
    events already use that name (an event attribute, a column robotale's logs have, a
    property the graph sets on events: ``order``), then ``object:<type>``; a type whose name
    cannot be a property is refused."""
    taken = {*event_columns, *schema.CSV_NAMES, *schema.CSV_NAMES.values(), *EVENT_OWN, "id"}
    columns = {}
    for name in types:
        if not schema.is_property_name(name) or len(name) > 90:
            raise InputError(
                f"{source}: the object type {name!r} cannot become a Neo4j name (use letters, "
                "digits, _ : . - and blanks, starting with a letter)."
            )
        if name in taken:
            columns[name] = f"{COLUMN_PREFIX}{name}"
    return columns


def check_attribute_names(source: Path, names: list[str], where: str) -> None:
    """Object attributes become Entity properties: refuse unusable or reserved names."""
    for name in names:
        if not schema.is_property_name(name):
            raise InputError(
                f"{source}: the {where} attribute {name!r} cannot become a Neo4j property name "
                "(use letters, digits, _ : . - and blanks, starting with a letter)."
            )
        if name in ENTITY_KEYS:
            raise InputError(
                f"{source}: the {where} attribute {name!r} has the name of the Entity node's own "
                f"{name!r}; rename it."
            )


def check_object_ids(source: Path, objects: pd.DataFrame, where: str = "object") -> None:
    """Ids must be given, unique, and free of the separator that lists several in a cell."""
    ids = objects["id"]
    empty = ids.isna() | (ids.astype(str).str.strip() == "")
    if empty.any():
        raise InputError(f"{source}: {_where(where, empty)} has no id.")
    separated = ids.astype(str).str.contains(SEPARATOR, regex=False)
    if separated.any():
        bad = ids[separated].iloc[0]
        raise InputError(
            f"{source}: the object id {bad!r} holds a comma, which robotale reads as a list of "
            "objects; give objects ids without commas."
        )
    repeated = ids.duplicated()
    if repeated.any():
        raise InputError(
            f"{source}: the object id {ids[repeated].iloc[0]!r} appears more than once."
        )


def _where(where: str, mask: pd.Series) -> str:
    return f"{where} {int(mask.to_numpy().argmax()) + 1}"


def entity_cells(event_ids: pd.Series, objects: Objects) -> dict[str, pd.Series]:
    """Per entity column, each event's objects of that type as one comma-separated cell (None
    where it has none), in the order of its relations."""
    kinds = objects.objects.set_index("id")["type"]
    links = objects.e2o.drop_duplicates(["event", "object"])
    links = links.assign(type=links["object"].map(kinds).to_numpy())
    cells = {}
    for kind in objects.types:
        mine = links[links["type"] == kind]
        joined = mine.groupby("event", sort=False)["object"].agg(SEPARATOR.join)
        cell = event_ids.map(joined).astype(object)
        cells[objects.column(kind)] = cell.where(cell.notna(), None)
    return cells


def require_known_objects(source: Path, objects: Objects) -> None:
    """Every relation must name objects the log lists."""
    known = set(objects.objects["id"].astype(str))
    for table, column, what in (
        (objects.e2o, "object", "event {owner!r} relates to"),
        (objects.o2o, "source", "an object-to-object relation starts at"),
        (objects.o2o, "target", "the object {owner!r} relates to"),
        (objects.changes, "object", "an attribute change names"),
    ):
        unknown = ~table[column].astype(str).isin(known)
        if unknown.any():
            row = table[unknown].iloc[0]
            owner = row.get("event", row.get("source"))
            raise InputError(
                f"{source}: {what.format(owner=owner)} the object {row[column]!r}, which the "
                "log's objects do not list."
            )
