"""Where a simulated run took place, for the Mission page's map: the field, the bases, the
obstacles (from the world file its manifest names) and the objects placed in that run (weeds,
targets: from the manifest).

A stored log keeps no manifest, so the sites of its runs are read when recordings are stored
and kept with the log's build (:func:`keep_sites`); a log stored from a CSV has none, and the
map then spans the positions the log records.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from neo4j import Driver

from robotale.ekg.columnar import results_folder
from robotale.errors import InputError
from robotale.eventlog.prepare import find_runs
from robotale.fame_runtime.manifest import RunManifest, read_manifest
from robotale.files import write_file
from robotale.results.logdata import current_build
from robotale.sim import scenarios
from robotale.sim.worldspec import World, load_world

#: the file beside a build's other results
SITES = "sites.json"
#: how a manifest names a shipped file (:func:`robotale.sim.scenarios.describe`)
SHIPPED = "robotale/sim/scenarios/"


def run_sites(root: Path) -> dict[str, dict[str, Any]]:
    """The site of every run under ``root`` that has a readable manifest, by case (the log is
    stored by then: a damaged manifest costs its run's map, not the log)."""
    sites = {}
    for run in find_runs(root):
        try:
            manifest = read_manifest(run)
        except (InputError, OSError):
            continue
        if manifest is not None:
            sites[run.name] = site_of(manifest)
    return sites


def site_of(manifest: RunManifest) -> dict[str, Any]:
    """One run's site; without a readable world file, only what the manifest says."""
    setup = manifest.get("setup") or {}
    site: dict[str, Any] = {
        "scenario": manifest.get("scenario"),
        "objects": [
            {"kind": o.get("kind"), "id": o.get("id"), "x": o.get("x"), "y": o.get("y")}
            for o in setup.get("objects") or []
        ],
        "homes": {name: start.get("home") for name, start in (setup.get("robots") or {}).items()},
        "field": None,
        "bases": [],
        "obstacles": [],
    }
    world = _world(manifest.get("world"))
    if world is not None:
        site["field"] = list(world.field)
        site["bases"] = [
            {"name": b.name, "x": b.position[0], "y": b.position[1], "radius": b.radius}
            for b in world.bases.values()
        ]
        site["obstacles"] = [
            {
                "name": o.name,
                "x": o.position[0],
                "y": o.position[1],
                "width": o.size[0],
                "depth": o.size[1],
                "yaw": o.yaw,
            }
            for o in world.obstacles
        ]
    return site


def _world(named: Any) -> World | None:
    if not isinstance(named, str) or not named:
        return None
    path = scenarios.FOLDER / named[len(SHIPPED) :] if named.startswith(SHIPPED) else Path(named)
    try:
        return load_world(path)
    except InputError:  # moved or changed since the run: the manifest's part still helps
        return None


def keep_sites(driver: Driver, name: str, sites: dict[str, dict[str, Any]]) -> None:
    """Keep ``sites`` with the current build of the stored log ``name``."""
    if sites:
        folder = results_folder(current_build(driver, name))
        write_file(folder / SITES, json.dumps(sites, indent=1).encode("utf-8"))


def stored_site(driver: Driver, name: str, case: str) -> dict[str, Any] | None:
    """The site of run ``case`` of the stored log ``name``, None when it has none."""
    path = results_folder(current_build(driver, name)) / SITES
    try:
        sites = json.loads(path.read_bytes())
    except (OSError, ValueError):
        return None
    site = sites.get(str(case)) if isinstance(sites, dict) else None
    return site if isinstance(site, dict) else None
