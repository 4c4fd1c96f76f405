"""Two simulated runs of the agri scenario and the collaboration discovered from them: the
driving model (it has a diagram) against what the runs show, for the model diff's tests."""

from __future__ import annotations

import warnings
from pathlib import Path

import pandas as pd


def agri_discovered(folder: Path, runs: int = 2, seed: int = 3) -> tuple[Path, Path, pd.DataFrame]:
    """(the agri model, the model discovered from ``runs`` runs of it, their log)."""
    from robotale.discovery.bpmn_writer import write_bpmn
    from robotale.discovery.collaboration import discover_collaboration
    from robotale.discovery.filters import LogFilter
    from robotale.eventlog.prepare import prepare
    from robotale.sim.batch import simulate_batch
    from robotale.sim.plans import plans, resolve_world

    world = resolve_world("agri")[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        simulate_batch(plans(world, "agri", runs=runs, seed=seed), folder / "runs", workers=0)
        log = prepare(folder / "runs")
    discovered = folder / "discovered.bpmn"
    discovered.write_text(write_bpmn(discover_collaboration(log, LogFilter())))
    return world.model, discovered, log
