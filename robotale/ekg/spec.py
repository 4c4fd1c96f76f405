"""An aggregation specification: steps that collapse events or entities into aggregate nodes.

The keys are those of OCEAN's ``AggrStep``, so a specification reads the same in both::

    steps:
      - aggr_type: ENTITIES            # or EVENTS
        ent_type: Container            # the entity type (ENTITIES only)
        group_by: [Status]             # properties and derived keys (see GROUP_KINDS)
        where: Weight >= 10            # optional, see robotale.ekg.where
        attr_aggrs:                    # optional
          - {name: Weight, function: AVG}

A group-by item is a property name, or one of the derived keys of robot logs: ``grid`` (a
spatial cell of ``size``), ``regions`` (named polygons or boxes), ``window`` (a time window)
and ``band`` (a value band). Everything is checked here, before Neo4j is touched; the checks
against the stored log (which properties exist) come when a step runs.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd
import yaml

from robotale.ekg.tables import check_name
from robotale.errors import InputError

AGGR_TYPES = ("ENTITIES", "EVENTS")
FUNCTIONS = ("SUM", "AVG", "MIN", "MAX", "MINMAX", "MULTISET")
_STEP_KEYS = {"aggr_type", "ent_type", "group_by", "where", "attr_aggrs"}


@dataclass(frozen=True)
class GroupKey:
    """One group-by item. ``kind`` is ``property`` or a derived key of :data:`GROUP_KINDS`;
    ``name`` is the aggregate property that holds its value."""

    kind: str
    name: str
    inputs: tuple[str, ...]  # the node properties it reads
    size: float = 0.0  # grid cell, window seconds, band width
    areas: tuple[tuple[str, tuple[tuple[float, float], ...]], ...] = ()  # regions: polygons


@dataclass(frozen=True)
class AttrAggr:
    name: str
    function: str

    def outputs(self) -> list[str]:
        """The aggregate properties this writes (MINMAX writes two)."""
        if self.function == "MINMAX":
            return [f"{self.name}_min", f"{self.name}_max"]
        return [f"{self.name}_{self.function.lower()}"]


@dataclass(frozen=True)
class AggrStep:
    aggr_type: str
    ent_type: str | None
    group_by: tuple[GroupKey, ...]
    where: str | None = None
    attr_aggrs: tuple[AttrAggr, ...] = ()
    source: dict[str, Any] = field(default_factory=dict, compare=False)  # as written

    @property
    def origin(self) -> str:
        """The label of the nodes it collapses."""
        return "Event" if self.aggr_type == "EVENTS" else "Entity"

    def reads(self) -> list[str]:
        """Every node property the step reads for its groups and attributes."""
        names = [n for key in self.group_by for n in key.inputs]
        names += [a.name for a in self.attr_aggrs]
        return list(dict.fromkeys(names))

    def text(self) -> str:
        """The step as one line of JSON (recorded with its aggregates)."""
        return json.dumps(self.source, sort_keys=True, default=str)


def read_spec(path: Path) -> list[AggrStep]:
    """The steps of the YAML file ``path``."""
    try:
        document = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    except OSError as error:
        raise InputError(f"The specification {path} cannot be read: {error.strerror}.") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        at = f" at line {mark.line + 1}" if mark is not None else ""
        raise InputError(f"The specification {path} is not valid YAML{at}.") from None
    return parse_spec(document, str(path))


def parse_spec(document: Any, where: str = "the specification") -> list[AggrStep]:
    """The steps of a specification already read (a mapping with ``steps``, or a list)."""
    steps = document.get("steps") if isinstance(document, dict) else document
    if not isinstance(steps, list) or not steps:
        raise InputError(f"{where} has no steps: give a list `steps:` of at least one step.")
    return [_step(item, f"step {n} of {where}") for n, item in enumerate(steps, 1)]


def _step(item: Any, what: str) -> AggrStep:
    if not isinstance(item, dict):
        raise InputError(f"{what.capitalize()} is not a mapping of aggr_type, group_by ...")
    unknown = sorted(set(map(str, item)) - _STEP_KEYS)
    if unknown:
        raise InputError(
            f"{what.capitalize()} has the unknown key {unknown[0]!r}; a step has "
            f"{', '.join(sorted(_STEP_KEYS))}."
        )
    kind = str(item.get("aggr_type", "")).upper()
    if kind not in AGGR_TYPES:
        raise InputError(f"{what.capitalize()} needs aggr_type ENTITIES or EVENTS.")
    entity_type = item.get("ent_type")
    if kind == "ENTITIES":
        if not entity_type:
            raise InputError(f"{what.capitalize()} aggregates entities: give their ent_type.")
        check_name(str(entity_type), f"ent_type of {what}")
    elif entity_type:
        raise InputError(f"{what.capitalize()} aggregates events: leave ent_type out.")
    group_by = item.get("group_by")
    if isinstance(group_by, str | dict):
        group_by = [group_by]
    if not isinstance(group_by, list) or not group_by:
        raise InputError(f"{what.capitalize()} needs a group_by list of at least one key.")
    keys = tuple(_group_key(key, f"group_by of {what}") for key in group_by)
    names = [key.name for key in keys]
    if len(set(names)) < len(names):
        raise InputError(f"The group_by of {what} names a key twice; give each one `as:`.")
    where = item.get("where")
    if where is not None and not isinstance(where, str):
        raise InputError(f"The where of {what} must be a text such as 'battery < 50'.")
    attrs = tuple(_attr(a, f"attr_aggrs of {what}") for a in item.get("attr_aggrs") or [])
    return AggrStep(
        kind, str(entity_type) if entity_type else None, keys, where or None, attrs, dict(item)
    )


def _attr(item: Any, what: str) -> AttrAggr:
    if not isinstance(item, dict) or "name" not in item or "function" not in item:
        raise InputError(f"Each item of the {what} needs a name and a function.")
    function = str(item["function"]).upper()
    if function not in FUNCTIONS:
        raise InputError(
            f"The {what} asks for the function {item['function']!r}; "
            f"there are {', '.join(FUNCTIONS)}."
        )
    return AttrAggr(check_name(str(item["name"]), what), function)


GROUP_KINDS = ("grid", "regions", "window", "band")


def _group_key(item: Any, what: str) -> GroupKey:
    if isinstance(item, str):
        return GroupKey("property", check_name(item, what), (item,))
    if not isinstance(item, dict) or len(set(item) - {"as"}) != 1:
        raise InputError(
            f"Each item of the {what} is a property name or one of "
            f"{', '.join(GROUP_KINDS)} with its settings."
        )
    kind = next(k for k in item if k != "as")
    options = item[kind]
    if kind not in GROUP_KINDS or not isinstance(options, dict):
        raise InputError(
            f"The {what} has {kind!r}; derived keys are {', '.join(GROUP_KINDS)}, each a "
            "mapping of settings."
        )
    key = _DERIVED[kind](options, f"{kind} in the {what}")
    name = check_name(str(item.get("as", key.name)), what)
    return GroupKey(key.kind, name, key.inputs, key.size, key.areas)


def _grid(options: dict[str, Any], what: str) -> GroupKey:
    x, y = _names(options, what, x="x", y="y")
    return GroupKey("grid", "cell", (x, y), _positive(options.get("size"), "size", what))


def _window(options: dict[str, Any], what: str) -> GroupKey:
    (prop,) = _names(options, what, property="timestamp")
    try:
        seconds = pd.Timedelta(str(options.get("size"))).total_seconds()
    except ValueError:
        seconds = math.nan
    return GroupKey("window", "window", (prop,), _positive(seconds, "size (e.g. 60s, 5min)", what))


def _band(options: dict[str, Any], what: str) -> GroupKey:
    (prop,) = _names(options, what, property=None)
    width = _positive(options.get("width"), "width", what)
    return GroupKey("band", f"{prop}_band", (prop,), width)


def _regions(options: dict[str, Any], what: str) -> GroupKey:
    x, y = _names(options, what, x="x", y="y")
    areas = options.get("areas")
    if not isinstance(areas, dict) or not areas:
        raise InputError(f"The {what} needs areas: a mapping of names to polygons or boxes.")
    return GroupKey("regions", "region", (x, y), 0.0, tuple(_area(n, a, what) for n, a in
                                                            areas.items()))  # fmt: skip


def _area(name: Any, shape: Any, what: str) -> tuple[str, tuple[tuple[float, float], ...]]:
    """A named area as a polygon; a box ``{box: [x0, y0, x1, y1]}`` becomes its four corners."""
    label = str(name)
    try:
        if isinstance(shape, dict) and list(shape) == ["box"]:
            x0, y0, x1, y1 = (float(v) for v in shape["box"])
            corners: tuple[tuple[float, float], ...] = ((x0, y0), (x1, y0), (x1, y1), (x0, y1))
        else:
            corners = tuple((float(p[0]), float(p[1])) for p in shape)
    except (TypeError, ValueError, IndexError, KeyError):
        corners = ()
    if len(corners) < 3 or not all(map(math.isfinite, (v for c in corners for v in c))):
        raise InputError(
            f"The area {label!r} of the {what} is neither a polygon ([[x, y], ...], three "
            "points or more) nor {box: [x0, y0, x1, y1]}."
        )
    return label, corners


def _names(options: dict[str, Any], what: str, **defaults: str | None) -> list[str]:
    found = []
    for option, default in defaults.items():
        value = options.get(option, default)
        if value is None:
            raise InputError(f"The {what} needs {option}: the property it reads.")
        found.append(check_name(str(value), what))
    return found


def _positive(value: Any, option: str, what: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number) or number <= 0:
        raise InputError(f"The {what} needs a positive {option}.")
    return number


_DERIVED = {"grid": _grid, "regions": _regions, "window": _window, "band": _band}


def spec_dict(step: AggrStep) -> dict[str, Any]:
    """The step as plain data (for ``--json``)."""
    return asdict(step)["source"] or {
        "aggr_type": step.aggr_type,
        "ent_type": step.ent_type,
        "where": step.where,
    }
