"""A run replayed straight from its recording (``robotale serve --bag``): the bag is prepared
into an event log in memory and the Mission page reads it from there, with no ingest into
Neo4j and nothing written to disk, so the replay ends with the dashboard that serves it."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from robotale.enhancement.mission import MissionRun, mission_run
from robotale.enhancement.timeline import case_timeline, run_list
from robotale.errors import InputError
from robotale.eventlog.logkinds import RECORDINGS, kind_of
from robotale.eventlog.logsource import log_name, open_log
from robotale.eventlog.runs import find_runs
from robotale.eventlog.schema import CASE, TIMESTAMP
from robotale.results.logdata import result_json
from robotale.results.site import run_sites


@dataclass
class Replay:
    """A prepared recording: its name on the dashboard, its events, the sites of its runs
    and the runs replayed so far."""

    name: str
    events: pd.DataFrame
    sites: dict[str, dict[str, Any]]
    runs: dict[str, MissionRun] = field(default_factory=dict)

    @property
    def cases(self) -> list[str]:
        """The runs it holds, in the order of their first event."""
        ordered = self.events.sort_values(TIMESTAMP, kind="stable")
        return [str(c) for c in ordered[CASE].astype("string").unique()]

    def run(self, case: str) -> MissionRun:
        """The run ``case``, computed once."""
        if not case:
            raise InputError("Name the run to replay (?case=).")
        if case not in self.runs:
            self.runs[case] = mission_run(self.events, case)
        return self.runs[case]

    def runs_json(self) -> bytes:
        """Its runs in start order, as the Timeline API answers for a stored log."""
        return result_json({"runs": run_list(self.events).to_dict(orient="records")})

    def timeline_json(self, case: str) -> bytes:
        """The timeline of run ``case`` (the first run when empty), as for a stored log."""
        return result_json(case_timeline(self.events, case or self.cases[0]).to_dict())


def open_replay(path: Path) -> Replay:
    """The recording at ``path`` (a bag directory, or a folder of them) prepared for replay;
    an :class:`InputError` naming ``path`` when it holds none."""
    if not path.is_dir() or kind_of(path) is not RECORDINGS:
        what = "does not exist" if not path.exists() else "is not a rosbag2 recording"
        raise InputError(f"{path} {what}: --bag takes a bag directory (with metadata.yaml).")
    find_runs(path)  # says which folder is not a bag before anything is read
    opened = open_log(path)
    return Replay(log_name(path), opened.events, run_sites(path))
