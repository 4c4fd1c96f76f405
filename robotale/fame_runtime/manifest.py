"""The run manifest: what a run of a mission records next to its bag, ``robotale-run.json``.

Like the tags (:mod:`robotale.fame_runtime.tags`) it is a contract between the part that runs a
mission and the parts that read its recordings: the simulator writes it
(:mod:`robotale.sim.run`, and :mod:`robotale.sim.batch` for a run whose worker died);
preparation takes the robots' types from it, the OCEL writer gives run objects its values as
attributes, and the dashboard finds the shipped model that drove the runs by its scenario.
Every field is optional to a reader: recordings made elsewhere have no manifest, or one with
only some fields (a crashed run has no ``robots``).
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any, TypedDict, cast

from robotale.errors import InputError
from robotale.files import write_file

#: the manifest's file name inside a run's folder
MANIFEST = "robotale-run.json"


class Outcome(TypedDict, total=False):
    status: str  # "ended", "time limit" or "crashed"
    reason: str  # why it did not end, in one line
    traceback: str  # where a crashed run raised


class RunManifest(TypedDict, total=False):
    """One run, as the simulator describes it (JSON; nested values are plain dicts)."""

    case: str  # the run's folder name and case id: run_0001
    scenario: str
    model: str  # the BPMN file, shipped ones by their place in the package
    world: str
    seed: int
    batch_seed: int
    index: int  # 1-based, in the batch
    start: str  # ISO time of the run's first simulated second, UTC
    duration: float  # simulated seconds
    wall_time: float
    outcome: Outcome
    settings: dict[str, Any]
    faults: list[dict[str, Any]]
    setup: dict[str, Any]
    #: robot instance -> its type (the pool that bound it): {"tractor_1": "Tractor"}
    robots: dict[str, Any]
    instances: dict[str, dict[str, Any]]
    failures: list[str]
    objects: list[dict[str, Any]]
    robots_final: dict[str, dict[str, Any]]
    weeds: dict[str, int]
    targets: dict[str, int]
    topics: dict[str, dict[str, Any]]


def manifest_text(manifest: RunManifest) -> str:
    """The manifest as its file holds it (also for a run uploaded to a remote place)."""
    return json.dumps(manifest, indent=2) + "\n"


def parse_manifest(data: str | bytes, where: object) -> RunManifest:
    """A manifest file's content; ``where`` (its path or URL) names it in the error."""
    try:
        manifest = json.loads(data)
    except (ValueError, UnicodeDecodeError) as error:
        raise InputError(f"{where} is not valid JSON: {error}.") from None
    if not isinstance(manifest, dict):
        raise InputError(f"{where} holds no JSON object, so it is no run manifest.")
    return cast(RunManifest, manifest)  # a JSON object; its keys are read with defaults


def write_manifest(folder: Path, manifest: RunManifest) -> Path:
    """Write ``manifest`` into the run folder ``folder`` (whole, or not at all)."""
    path = folder / MANIFEST
    write_file(path, manifest_text(manifest))
    return path


def read_manifest(folder: Path) -> RunManifest | None:
    """The manifest of the run in ``folder``; None when it has none."""
    path = folder / MANIFEST
    if not path.is_file():
        return None
    return parse_manifest(path.read_bytes(), path)


def read_manifests(runs: Iterable[Path]) -> dict[str, RunManifest]:
    """The manifests of the runs that have one, by case id (the run folder's name)."""
    found = {run.name: read_manifest(run) for run in runs}
    return {case: manifest for case, manifest in found.items() if manifest is not None}
