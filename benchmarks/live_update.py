"""The monitor's graph update in its own process, early and late in a long live run: does its
work follow what is new, or the run's length?

    python benchmarks/live_update.py [--robots 20] [--at 60 540] [--updates 20] [--seed 1]

The tags of ``--robots`` robots as ``benchmarks/live.py`` publishes them (a tag every 1 to 2 s
each, starts and completes of survey, measure, report in turn) are made in memory. For each
moment of ``--at`` (seconds into the run) a monitor's graph is grown up to 20 s before it (an
update every 10 s), then ``--updates`` updates follow, one per second of run, as the monitor
makes them: the events made again of the new tags only (:class:`LiveEvents`) and the update
told how many first events are as they were (``incremental``), the same with the class tables
made of the whole log at each update (``tablesbefore``, as before they were grown), and the
events made of every tag heard and the update given the whole log, class tables whole
(``whole``, what the monitor did first). The ways and the moments are interleaved update by
update. Neo4j is left out (its
transaction replaced by one that answers element ids): this measures the process' own part,
which ran every second whatever Neo4j did.

Printed per moment and way: the median and p90 CPU time of an update (this thread's) and its
median wall time, the events held then; the growth of each way (its median CPU at the last
moment over the first); the load average before and after. Checked after the updates: the
incremental way's events equal those made of every tag, its event keys and DF edges the whole
way's, and its DF_C values (count, mean, median) those of ``tablesbefore``.
"""

from __future__ import annotations

import argparse
import itertools
import os
import random
import sys
import time
from typing import Any

import numpy as np

T0 = 1_800_000_000.0


def run_tags(robots: int, seconds: float, seed: int) -> list[Any]:
    """The robots' tags for ``seconds``, in stamp order (as heard)."""
    from live import robots_of, tag_steps

    from robotale.fame_runtime.tags import Tag

    tags = []
    for robot in robots_of(robots):
        steps = tag_steps(robot, seed)
        stamp = T0 + random.Random(robot).uniform(0, 1)
        while stamp < T0 + seconds:
            gap, activity, lifecycle = next(steps)
            tags.append(Tag(stamp, robot, activity, lifecycle))
            stamp += gap
    return sorted(tags, key=lambda tag: tag.stamp)


class _Loader:
    """Neo4j's batches left out: element ids made up for the nodes created."""

    ids = itertools.count()

    def __init__(self, *_: Any, **__: Any) -> None:
        pass

    def run(self, query: str, columns: dict[str, list[Any]], *_: Any, **__: Any) -> list[str]:
        if "create" not in query and "merge" not in query:
            return []
        rows = len(next(iter(columns.values()))) if columns else 0
        return [f"4:x:{next(self.ids)}" for _ in range(rows)]

    def events(self, events: Any, *_: Any, **__: Any) -> np.ndarray:
        return np.array([f"4:e:{next(self.ids)}" for _ in range(len(events))], dtype=object)


class _Transaction:
    def run(self, *_: Any, **__: Any) -> _Transaction:
        return self

    def consume(self) -> None:
        return None


def _offline() -> None:
    """The live log's writes made without Neo4j."""
    from robotale.ekg import growing

    def write(_driver: Any, _name: str, work: Any, *args: Any) -> None:
        work(_Transaction(), *args, lambda: None)

    growing.Loader = _Loader  # type: ignore[misc,assignment]
    growing.write_transaction = write
    growing.write_df_c = lambda *_: None
    growing.write_begins = lambda *_, **__: None


def _graph() -> Any:
    """A live log as :class:`GrowingLog` makes one, without the write lock and the schema."""
    from robotale.ekg.growing import GrowingLog, _Stored

    graph = object.__new__(GrowingLog)
    graph.driver, graph.name, graph.run, graph.begun = None, "run", "bench", True
    graph.stored, graph.log, graph.summary = _Stored(), None, {}
    graph.types, graph.keys, graph.reused = [], [], 0
    graph.classes, graph.classes_reused = [], 0
    return graph


class _WholeClasses:
    """The class tables made of the whole log at each update, as before they were grown."""

    last = np.empty(0, dtype=np.int64)

    def __init__(self, key: list[str]) -> None:
        self.key = key

    def grown(self, tables: Any, _same: int) -> tuple[_WholeClasses, Any]:
        from robotale.ekg.tables import class_tables

        return self, class_tables(tables, self.key)


def _whole_classes(graph: Any, events: Any) -> None:
    """``graph`` makes its class tables of the whole log (from its first update on)."""
    from robotale.ekg.keys import built_keys, default_entities

    if not graph.classes:
        keys = built_keys(default_entities(events.columns))
        graph.classes = [_WholeClasses(key.split(",")) for key in keys]


class Incremental:
    """The monitor's way: events made again of the new tags, the first ones taken over."""

    def __init__(self, tags: list[Any]) -> None:
        from robotale.results.live import LiveEvents

        self.tags, self.graph, self.made, self.heard = tags, _graph(), LiveEvents(), 0

    def upto(self, heard: int) -> None:
        events, _, _, kept = self.made.add("run", self.tags[self.heard : heard])
        self.heard = heard
        self.graph.update(events, same=kept)


class Tablesbefore(Incremental):
    """The monitor's way with the class tables made of the whole log (as before they grew)."""

    def upto(self, heard: int) -> None:
        events, _, _, kept = self.made.add("run", self.tags[self.heard : heard])
        self.heard = heard
        _whole_classes(self.graph, events)
        self.graph.update(events, same=kept)


class Whole:
    """The way before: the events made of every tag heard, the whole log compared."""

    def __init__(self, tags: list[Any]) -> None:
        self.tags, self.graph = tags, _graph()

    def upto(self, heard: int) -> None:
        from robotale.results.live import tags_events

        events = tags_events("run", self.tags[:heard])
        _whole_classes(self.graph, events)
        self.graph.update(events)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=20)
    parser.add_argument("--at", type=float, nargs="+", default=[60.0, 540.0])
    parser.add_argument("--updates", type=int, default=20)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    _offline()
    tags = run_tags(args.robots, max(args.at) + 1, args.seed)
    stamps = np.array([tag.stamp for tag in tags])

    def heard(seconds: float) -> int:
        return int(np.searchsorted(stamps, T0 + seconds))

    ways = {
        (way.__name__.lower(), at): way(tags)
        for at in args.at
        for way in (Incremental, Tablesbefore, Whole)
    }
    for (_, at), side in ways.items():
        for seconds in np.arange(10.0, at - 20, 10.0):
            side.upto(heard(seconds))
    cpu: dict[tuple[str, float], list[float]] = {key: [] for key in ways}
    wall: dict[tuple[str, float], list[float]] = {key: [] for key in ways}
    for update in range(args.updates):
        for key, side in ways.items():
            until = heard(key[1] - 20 + update + 1)
            began, spent = time.perf_counter(), time.thread_time()
            side.upto(until)
            cpu[key].append(time.thread_time() - spent)
            wall[key].append(time.perf_counter() - began)
    for key, side in ways.items():
        way, at = key
        p50, p90 = np.percentile(cpu[key], [50, 90]) * 1000
        print(f"{way:11s} at {at:4.0f} s ({len(side.graph.stored.nodes):6d} events): CPU "
              f"median {p50:6.1f} ms, p90 {p90:6.1f} ms; wall median "
              f"{1000 * np.median(wall[key]):6.1f} ms")  # fmt: skip
    first, last = min(args.at), max(args.at)
    for way in ("incremental", "tablesbefore", "whole"):
        ratio = np.median(cpu[(way, last)]) / np.median(cpu[(way, first)])
        print(f"growth of {way}: median CPU at {last:.0f} s over {first:.0f} s {ratio:.2f}x")
    print(f"check: {_check(ways, tags, heard, args)}")
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


def _check(ways: dict[tuple[str, float], Any], tags: list[Any], heard: Any, args: Any) -> str:
    """The incremental way's events, keys and DF edges against the whole way's, at the end."""
    import pandas as pd

    from robotale.results.live import tags_events

    for at in args.at:
        grown, whole = ways[("incremental", at)], ways[("whole", at)]
        before = ways[("tablesbefore", at)].graph.stored
        assert (len(before.df_c), len(before.begins)) == (
            len(grown.graph.stored.df_c),
            len(grown.graph.stored.begins),
        ), at
        assert sorted(before.df_c.values()) == sorted(grown.graph.stored.df_c.values()), at
        count = heard(at - 20 + args.updates)
        pd.testing.assert_frame_equal(grown.made.events, tags_events("run", tags[:count]))
        mine, theirs = grown.graph.stored, whole.graph.stored
        assert mine.keys.keys.tolist() == theirs.keys.keys.tolist(), at
        assert set(mine.df) == set(theirs.df) and len(mine.df) == len(theirs.df), at
        assert grown.graph.reused > 0, "the first events were never taken over"
        assert grown.graph.classes_reused > 0, "the class tables' edges were never kept"
    return (
        "events, event keys and DF edges equal the whole way's, DF_C values those of the "
        "class tables made whole, at every moment: yes"
    )


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    sys.exit(main())
