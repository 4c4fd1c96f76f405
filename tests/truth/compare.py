"""robotale's answers on a simulated batch set against the oracle's (:mod:`oracle`).

:func:`disagreements` runs robotale's analysis on a batch's prepared log and lists, per
subject, every place where it differs from the truth. The property tests assert on these
lists; ``scripts/verify_findings.py`` prints them as a table over many seeds.
"""

from __future__ import annotations

import json
import math
import warnings
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import oracle
import pandas as pd

#: tolerances: times are recorded to the nanosecond, batteries sampled at different instants
SECONDS = 0.002
BATTERY_POINTS = 1.0  # percentage points
BATTERY_SHARE = 0.1  # or this share of the use, whichever is larger

SUBJECTS = (
    "messages",
    "lost",
    "delayed",
    "resends",
    "activities",
    "durations",
    "dfg",
    "battery",
    "overlap",
)
#: robots this close (metres, 3D) at one moment met; robotale pairs positions up to a quarter
#: second apart (half the 2 Hz sample period) and robots move up to 1.2 m/s, so a pair counts
#: as met or apart for sure only under NEAR or over FAR
MEET, NEAR, FAR = 1.0, 0.6, 1.6
#: robotale pairs two robots' positions at most this far apart in time (seconds)
PAIRED = 0.26


@dataclass(frozen=True)
class Disagreement:
    subject: str
    case: str
    item: str
    truth: object
    robotale: object

    def row(self, seed: int | str = "") -> list[str]:
        return [str(seed), self.subject, self.case, self.item, str(self.truth), str(self.robotale)]


def prepared(batch: Path) -> pd.DataFrame:
    """The batch's event log as ``robotale prepare`` makes it."""
    from robotale.eventlog.prepare import prepare

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return prepare(batch)


def disagreements(
    batch: Path, log: pd.DataFrame, delay: float, subjects=SUBJECTS
) -> list[Disagreement]:
    runs = oracle.load_batch(batch)
    found: list[Disagreement] = []
    checks = {
        "messages": _messages,
        "lost": _lost,
        "delayed": _delayed,
        "resends": _resends,
        "activities": _activities,
        "durations": _durations,
        "dfg": _dfg,
        "battery": _battery,
        "overlap": _overlap,
    }
    table = None
    for subject in subjects:
        if subject in ("messages", "lost", "delayed", "resends"):
            table = _message_table(log, delay) if table is None else table
            found += checks[subject](runs, table, delay)
        else:
            found += checks[subject](runs, log)
    return found


# -- messages ------------------------------------------------------------------------------------


#: one analysis per log and threshold; the log is kept with its table, since an id is only
#: unique while its object lives (another seed's log could otherwise be given this one's)
_TABLES: dict[tuple[int, float], tuple[pd.DataFrame, pd.DataFrame]] = {}
KEPT_TABLES = 16


def _message_table(log: pd.DataFrame, delay: float) -> pd.DataFrame:
    from robotale.enhancement.communication import communication_perspective

    key = (id(log), delay)
    cached = _TABLES.get(key)
    if cached is None or cached[0] is not log:
        perspective = communication_perspective(log, delay_threshold=delay)
        table = perspective.tables.get("messages")
        table = pd.DataFrame(columns=["case", "msg_id"]) if table is None else table
        if len(_TABLES) >= KEPT_TABLES:  # the oldest go: many seeds in one process
            del _TABLES[next(iter(_TABLES))]
        _TABLES[key] = cached = (log, table)
    return cached[1]


def _by_id(table: pd.DataFrame) -> dict[tuple[str, str], pd.Series]:
    return {(row["case"], row["msg_id"]): row for _, row in table.iterrows()}


def _messages(runs, table, delay) -> list[Disagreement]:
    """Every message sent is in robotale's table, and nothing else is."""
    found = []
    rows = _by_id(table)
    truth = {(m.case, m.msg_id) for run in runs for m in oracle.messages(run)}
    for case, msg_id in sorted(truth - set(rows)):
        found.append(Disagreement("messages", case, msg_id, "sent", "missing"))
    for case, msg_id in sorted(set(rows) - truth):
        found.append(Disagreement("messages", case, msg_id, "never sent", "listed"))
    return found


def _lost(runs, table, delay) -> list[Disagreement]:
    """A message robotale calls lost was not delivered, and one it calls received was."""
    found = []
    rows = _by_id(table)
    for run in runs:
        for message in oracle.messages(run):
            row = rows.get((run.case, message.msg_id))
            if row is None:
                continue
            said_lost = bool(row.get("lost", False))
            if said_lost and message.delivered:
                truth = f"delivered to {', '.join(message.receivers)}"
                found.append(Disagreement("lost", run.case, message.msg_id, truth, "lost"))
            elif not said_lost and not message.delivered and bool(row.get("received", False)):
                truth = f"not delivered ({', '.join(message.drops) or 'nobody waited'})"
                found.append(Disagreement("lost", run.case, message.msg_id, truth, "received"))
    return found


def _delayed(runs, table, delay) -> list[Disagreement]:
    """With an explicit threshold, a message is delayed exactly when its latency exceeds it;
    robotale's latency is the truth's."""
    found = []
    rows = _by_id(table)
    for run in runs:
        for message in oracle.messages(run):
            row = rows.get((run.case, message.msg_id))
            if row is None or message.latency is None:
                continue
            latency = row.get("latency")
            if latency is None or pd.isna(latency):
                continue  # not observed as received: _lost judges that
            if abs(float(latency) - message.latency) > SECONDS:
                found.append(
                    Disagreement(
                        "delayed",
                        run.case,
                        f"{message.msg_id} latency",
                        round(message.latency, 4),
                        round(float(latency), 4),
                    )
                )
            truly = message.slowest > delay
            if bool(row.get("delayed", False)) != truly:
                found.append(
                    Disagreement(
                        "delayed", run.case, message.msg_id, truly, bool(row.get("delayed"))
                    )
                )
    return found


def _resends(runs, table, delay) -> list[Disagreement]:
    """Each resend robotale names repeats a message the truth says it repeats, and every
    true resend is found."""
    found = []
    said: set[tuple[str, str, str]] = set()
    column = next((c for c in ("resent_as", "resend_of") if c in table.columns), None)
    for _, row in table.iterrows():
        value = row.get(column) if column else None
        if value is None or (not isinstance(value, str) and pd.isna(value)) or value == "":
            continue
        for other in str(value).replace(";", ",").split(","):
            other = other.strip()
            if other:
                pair = (row["msg_id"], other) if column == "resent_as" else (other, row["msg_id"])
                said.add((row["case"], *pair))
    truth = {
        (run.case, m.resend_of, m.msg_id)
        for run in runs
        for m in oracle.messages(run)
        if m.resend_of is not None
    }
    # a chain m1 -> m2 -> m3 may be named m1 -> m3: compare the repeated messages' groups
    truth_groups = _groups(truth)
    for case, original, resend in sorted(said):
        if truth_groups.get((case, resend)) != truth_groups.get((case, original)) or (
            truth_groups.get((case, resend)) is None
        ):
            found.append(
                Disagreement("resends", case, f"{resend} as a resend of {original}", "no", "yes")
            )
    said_groups = _groups(said)
    for case, original, resend in sorted(truth):
        if said_groups.get((case, resend)) is None:
            found.append(
                Disagreement("resends", case, f"{resend} as a resend of {original}", "yes", "no")
            )
    return found


def _groups(pairs: set[tuple[str, str, str]]) -> dict[tuple[str, str], str]:
    """Each message of a resend chain mapped to the chain's first message."""
    parent: dict[tuple[str, str], tuple[str, str]] = {}

    def root(key):
        while key in parent:
            key = parent[key]
        return key

    for case, original, resend in sorted(pairs):
        a, b = root((case, original)), root((case, resend))
        if a != b:
            parent[b] = a
    keys = {(c, o) for c, o, _ in pairs} | {(c, r) for c, _, r in pairs}
    return {key: root(key)[1] for key in keys}


# -- activities ----------------------------------------------------------------------------------


def _instances(log: pd.DataFrame) -> pd.DataFrame:
    from robotale.enhancement.context import analysis_of

    return analysis_of(log).instances()


def _activities(runs, log) -> list[Disagreement]:
    """robotale finds as many instances of each robot's activity as ended in truth."""
    instances = _instances(log)
    counted = instances.groupby(["robot", "concept:name"]).size().to_dict()
    found = []
    for (robot, activity), count in sorted(oracle.activity_counts(runs).items()):
        got = int(counted.get((robot, activity), 0))
        if got != count:
            found.append(Disagreement("activities", "all", f"{robot} {activity}", count, got))
    return found


def _durations(runs, log) -> list[Disagreement]:
    """The mean duration robotale computes per robot and activity is the true one."""
    instances = _instances(log)
    if "duration" not in instances.columns:
        return [Disagreement("durations", "all", "duration column", "present", "absent")]
    means = instances.groupby(["robot", "concept:name"])["duration"].mean().to_dict()
    found = []
    for key, truth in sorted(oracle.mean_durations(runs).items()):
        got = means.get(key)
        if got is None or abs(float(got) - truth) > 0.01 + 0.001 * truth:
            item = " ".join(key)
            found.append(
                Disagreement(
                    "durations",
                    "all",
                    item,
                    round(truth, 3),
                    None if got is None else round(got, 3),
                )
            )
    return found


def _dfg(runs, log) -> list[Disagreement]:
    """Each robot's DFG counts every instance: interrupted, cancelled and cut short included."""
    from robotale.discovery.dfg import discover_dfg

    found = []
    rows = oracle.activity_instances(runs)
    ended = Counter((r["robot"], r["activity"]) for r in rows if r["outcome"] in ENDED)
    cut = Counter((r["robot"], r["activity"]) for r in rows if r["outcome"] not in ENDED)
    for robot in sorted({robot for robot, _ in ended + cut}):
        graph = discover_dfg(log[log["robot"] == robot])
        nodes = {node.id: node for node in graph.nodes if node.kind == "activity"}
        for owner, activity in sorted(set(ended) | set(cut)):
            if owner != robot:
                continue
            node = nodes.get(activity)
            count = node.count if node is not None else 0
            unfinished = (node.properties or {}).get("unfinished", 0) if node is not None else 0
            truth = (ended[(robot, activity)], cut[(robot, activity)])
            if (count, unfinished) != truth:
                item = f"{robot} {activity} (ended, unfinished)"
                found.append(Disagreement("dfg", "all", item, truth, (count, unfinished)))
    return found


#: the outcomes of an activity instance that ended (the others: its robot died, the run ended)
ENDED = ("completed", "interrupted", "cancelled")


# -- battery -------------------------------------------------------------------------------------


def _battery(runs, log) -> list[Disagreement]:
    """Battery used per robot and run: what robotale says against the true levels' drops."""
    from robotale.enhancement.battery import battery_perspective

    perspective = battery_perspective(log)
    energy = perspective.tables.get("energy")
    if energy is None or energy.empty:
        return [Disagreement("battery", "all", "energy table", "per robot and run", "none")]
    said = {(row["case"], row["robot"]): float(row["used"]) for _, row in energy.iterrows()}
    found = []
    windows = _observed(runs, log)
    truth = oracle.battery_use(runs, {key: window[:2] for key, window in windows.items()})
    for key, used in sorted(truth.items()):
        got = said.get(key)
        margin = max(BATTERY_POINTS, BATTERY_SHARE * used, windows[key][2])
        if got is None or abs(got - used) > margin:
            found.append(
                Disagreement(
                    "battery",
                    key[0],
                    key[1],
                    round(used, 2),
                    None if got is None else round(got, 2),
                )
            )
    summary = perspective.summary
    for name in ("used_while_waiting",):
        if isinstance(summary.get(name), int | float) and summary[name] < 0:
            found.append(Disagreement("battery", "all", name, ">= 0", summary[name]))
    return found


#: the battery topic's period: a log's level at an event is the robot's next reading, up to
#: this many seconds later
BATTERY_PERIOD = 1.0


def _observed(runs, log: pd.DataFrame) -> dict[tuple[str, str], tuple[float, float, float]]:
    """Per (case, robot), the time from the robot's first level in the log to its last: a log
    has levels only at a robot's events, so that is the time whose battery use it can show (a
    robot without events has none). Each level is a battery reading near its event: the
    window runs between the true samples nearest those readings; the third value is how
    much the true level moved around the two readings (a margin for where they fell)."""
    rows = log.dropna(subset=["battery"]).sort_values("time:timestamp", kind="stable")
    keys = [rows[CASE_COLUMN].astype(str), rows["robot"]]
    times = rows["time:timestamp"].map(pd.Timestamp.timestamp)
    first = rows.assign(t=times).groupby(keys)[["t", "battery"]].first()
    last = rows.assign(t=times).groupby(keys)[["t", "battery"]].last()
    samples: dict[tuple[str, str], list[tuple[float, float]]] = {}
    for run in runs:
        for sample in run.samples:
            key = (run.case, sample["robot"])
            samples.setdefault(key, []).append((sample["t"], sample["battery"] * 100.0))
    windows = {}
    for key in first.index:
        own = samples.get(key, [])
        begin, begin_spread = _reading(own, *first.loc[key])
        end, end_spread = _reading(own, *last.loc[key])
        windows[key] = (begin, end, begin_spread + end_spread)
    return windows


def _reading(samples: list[tuple[float, float]], at: float, level: float) -> tuple[float, float]:
    """The time of the true sample nearest the reading a log's ``level`` at ``at`` shows: the
    one closest to that level within a battery period of ``at`` (the next reading, or the
    last one where the run ended before another came); and how far the true level moved
    within that period, the uncertainty a reading between two samples leaves."""
    near = [(abs(b - level), t, b) for t, b in samples if abs(t - at) <= BATTERY_PERIOD]
    if not near:
        return at, 0.0
    levels = [b for _, _, b in near]
    return min(near)[1], max(levels) - min(levels)


# -- space ---------------------------------------------------------------------------------------


def _overlap(runs, log) -> list[Disagreement]:
    """Robots robotale says were at the same place at the same moment (in 3D) were there, and
    those that truly were are found."""
    from robotale.enhancement.encounters import encounters, positions

    placed = positions(log)
    met = encounters(placed, metres=MEET, seconds=PAIRED)
    said = {(str(r[CASE_COLUMN]), *sorted((r["robot"], r["other"]))) for _, r in met.iterrows()}
    # a log has positions only around its events (a robot standing idle before its first tag
    # has none): the truth is judged at the moments the log could show
    stamps = {
        key: np.sort(group["time:timestamp"].map(pd.Timestamp.timestamp).to_numpy())
        for key, group in placed.groupby([CASE_COLUMN, "robot"])
    }

    def seen(case: str, robot: str, t: float) -> bool:
        times = stamps.get((case, robot))
        if times is None or not len(times):
            return False
        i = np.searchsorted(times, t)
        near = [times[j] for j in (i - 1, i) if 0 <= j < len(times)]
        # within half the pairing window of the instant: the two robots' positions are then
        # close enough in time for robotale to pair them
        return min(abs(t - n) for n in near) <= PAIRED / 2

    # a meeting is owed only at instants the log shows both robots; "apart" holds only if
    # the robots were apart at every instant, shown or not: two positions a tenth of a
    # second apart can each lie over a quarter second from the nearest truth sample
    shown = oracle.closest(runs, seen)
    anywhere = oracle.closest(runs)
    found = []
    for key, apart in sorted(anywhere.items()):
        item = f"{key[1]} and {key[2]}"
        near = shown.get(key, math.inf)
        if near <= NEAR and key not in said:
            found.append(Disagreement("overlap", key[0], item, f"met ({near:.2f} m)", "not"))
        elif apart > FAR and key in said:
            found.append(Disagreement("overlap", key[0], item, f"apart ({apart:.2f} m)", "met"))
    return found


CASE_COLUMN = "case:concept:name"


def _rounded(value: float | None, digits: int) -> float | None:
    return None if value is None else round(float(value), digits)


def table_text(rows: list[list[str]]) -> str:
    """A plain text table (the first row is the header)."""
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    return "\n".join(
        "  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)) for row in rows
    )


def as_json(found: list[Disagreement]) -> str:
    return json.dumps([d.__dict__ for d in found], default=str, indent=1)
