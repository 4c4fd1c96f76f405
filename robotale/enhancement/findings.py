"""The five questions an analyst of a robot mission asks, answered in plain sentences.

1. What is the typical sequence, and its main variants?
2. What delayed the runs (the bottlenecks, ranked by how much longer they make a run)?
3. Where did each robot work, and were robots at the same place at the same moment?
4. Did battery affect the mission?
5. Which messages were delayed, lost or resent (one example each)?

Each :class:`Answer` holds its sentences, the numbers behind them (``facts``) and the evidence a
reader can open: a node of the process graph (``node``: activity and robot), the runs
(``runs``) and one run's timeline (``timeline``). The numbers come from the perspectives
(performance, bottlenecks, battery, communication), each computed once; what they do not give
(the robots' areas and their overlap, the runs with a low-battery moment) is computed here.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any

import pandas as pd

from robotale.discovery.graph import json_ready
from robotale.enhancement.battery import battery_perspective
from robotale.enhancement.bottlenecks import ALPHA, find_bottlenecks
from robotale.enhancement.communication import communication_perspective
from robotale.enhancement.context import LogAnalysis, analysis_of
from robotale.enhancement.encounters import (
    METRES,
    SECONDS,
    encounters,
    positions,
    region_overlaps,
    run_regions,
)
from robotale.enhancement.performance import ARROW, performance_perspective
from robotale.enhancement.result import Perspective
from robotale.eventlog.schema import CASE, ROBOT, X, Y, Z
from robotale.thresholds import LOW_BATTERY_PERCENT

#: how many variants and bottlenecks an answer names
MAIN = 3


@dataclass(slots=True)
class Answer:
    key: str
    question: str
    sentences: list[str] = field(default_factory=list)
    facts: dict[str, Any] = field(default_factory=dict)
    evidence: list[dict[str, Any]] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return json_ready(
            {
                "key": self.key,
                "question": self.question,
                "sentences": self.sentences,
                "facts": self.facts,
                "evidence": self.evidence,
            }
        )


@dataclass(slots=True)
class Findings:
    answers: list[Answer]
    perspectives: dict[str, Perspective]
    runs: pd.DataFrame

    def answer(self, key: str) -> Answer:
        return next(a for a in self.answers if a.key == key)

    def timeline_cases(self, limit: int = 4) -> list[str]:
        """The runs the evidence points at, then the longest run: the timelines worth
        drawing."""
        cases: list[str] = []
        for answer in self.answers:
            cases += [e["case"] for e in answer.evidence if e["kind"] == "timeline"]
        if not self.runs.empty:
            cases.append(str(self.runs.sort_values("duration").iloc[-1]["case"]))
        return list(dict.fromkeys(cases))[:limit]

    def to_dict(self) -> dict[str, Any]:
        return {"answers": [a.to_dict() for a in self.answers]}


def find(
    log: pd.DataFrame | LogAnalysis,
    *,
    threshold: float = LOW_BATTERY_PERCENT,
    delay_threshold: float | None = None,
) -> Findings:
    """The answers to the five questions for ``log`` (``threshold``: the battery level, in
    percent, below which a robot's battery counts as low; ``delay_threshold``: the latency in
    seconds above which a message is delayed, else the rule of
    :mod:`robotale.enhancement.delays`)."""
    # one analysis for all: the activity instances, steps, case durations and the message
    # table are built once; the messages come first so the bottlenecks' queueing reuses them.
    # The spatial perspective is not needed: the areas are two numbers per robot.
    analysis = analysis_of(log)
    communication = communication_perspective(analysis, delay_threshold=delay_threshold)
    perspectives = {
        "performance": performance_perspective(analysis),
        "bottlenecks": find_bottlenecks(analysis),
        "battery": battery_perspective(analysis, threshold=threshold),
        "communication": communication,
    }
    performance = perspectives["performance"]
    runs = performance.tables.get("cases", pd.DataFrame(columns=["case", "duration"]))
    answers = [
        sequence_answer(performance),
        delay_answer(perspectives["bottlenecks"], performance, runs),
        robot_answer(analysis.log, performance),
        battery_answer(perspectives["battery"], runs),
        message_answer(perspectives["communication"]),
    ]
    return Findings(answers, perspectives, runs)


# -- 1. the typical sequence -------------------------------------------------------------------


def sequence_answer(performance: Perspective) -> Answer:
    answer = Answer("sequence", "What is the typical sequence, and its main variants?")
    if not performance.has_data:
        answer.sentences.append(_sentence(performance.message))
        return answer
    variants = performance.tables["variants"]
    runs = int(performance.summary["cases"])
    top = variants.iloc[0]
    answer.facts = {
        "runs": runs,
        "variants": len(variants),
        "main": [
            {"variant": v["variant"], "runs": int(v["cases"]), "share": float(v["share"])}
            for _, v in variants.head(MAIN).iterrows()
        ],
        "median_duration": float(performance.summary["case_duration_median"]),
    }
    answer.sentences.append(
        f"{_count(runs, 'run')} follow {_count(len(variants), 'variant')}; "
        f"the most common ({int(top['cases'])} of {runs}, {top['share']:.0%}) is "
        f"{_path(top['variant'])}, and takes {seconds_text(top['median'])} (median)."
    )
    for _, other in variants.iloc[1:MAIN].iterrows():
        answer.sentences.append(
            f"{int(other['cases'])} of {runs} runs ({other['share']:.0%}) differ from it: "
            f"{variant_difference(top['variant'], other['variant'])}; they take "
            f"{seconds_text(other['median'])} (median)."
        )
    answer.evidence.append({"kind": "runs", "label": "the runs and their variants"})
    return answer


def variant_difference(common: str, other: str) -> str:
    """What ``other`` does that ``common`` does not, and the reverse, counting repeats; the
    same activities in another order when neither."""
    mine, theirs = Counter(common.split(ARROW)), Counter(other.split(ARROW))
    parts = [
        f"{word} {_listed(extra)}"
        for word, extra in (("with", theirs - mine), ("without", mine - theirs))
        if extra
    ]
    return ", ".join(parts) if parts else "the same activities in another order"


def _listed(counts: Counter) -> str:
    return ", ".join(f"{name}" + (f" ×{n}" if n > 1 else "") for name, n in sorted(counts.items()))


# -- 2. delays and bottlenecks -----------------------------------------------------------------


def delay_answer(bottlenecks: Perspective, performance: Perspective, runs: pd.DataFrame) -> Answer:
    answer = Answer("delays", "What delayed the runs, and where are the bottlenecks?")
    if not bottlenecks.has_data:
        answer.sentences.append(_sentence(bottlenecks.message))
        return answer
    _one_run_of_days(runs, answer)
    left_out = int(bottlenecks.summary.get("aborted_runs_left_out", 0))
    if left_out:
        answer.facts["aborted_runs_left_out"] = left_out
        answer.sentences.append(
            f"Runs are compared with runs of the same outcome: the completed runs against each "
            f"other, leaving out {_count(left_out, 'run')} that did not complete."
        )
    ranking = trusted_first(bottlenecks.table).head(MAIN)
    answer.facts["bottlenecks"] = [
        {
            "rank": int(row["rank"]),
            "p_value": _value(row.get("p_value")),
            "kind": row["kind"],
            "activity": row["activity"],
            "robot": _value(row.get("robot")),
            "delay_per_case": float(row["delay_per_case"]),
            "runs": int(row["cases"]),
        }
        for _, row in ranking.iterrows()
    ]
    for _, row in ranking.iterrows():
        answer.sentences.append(f"{row['rank']}. {_sentence(row['explanation'])}")
        robot = _value(row.get("robot"))
        label = f"{row['activity']}" + (f" by {robot}" if robot else "")
        # a step between two activities is shown at the node it leads to
        node = str(row["activity"]).split(ARROW)[-1]
        answer.evidence.append({"kind": "node", "label": label, "activity": node, "robot": robot})
    slowest = _slowest_run(runs)
    if slowest is not None:
        answer.evidence.append(
            {"kind": "timeline", "label": f"the slowest run, {slowest}", "case": slowest}
        )
    share = performance.summary.get("waiting_share") if performance.has_data else None
    if share is not None:
        answer.facts["waiting_share"] = float(share)
        answer.sentences.append(
            f"Between activities the robots wait {share:.0%} of their time in the runs."
        )
    return answer


def _one_run_of_days(runs: pd.DataFrame, answer: Answer) -> None:
    """A log read as one run that lasts several days (no case column) counts the nights
    between its sessions as waiting: the answer says so before its ranking."""
    if len(runs) != 1 or not {"start", "end"} <= set(runs.columns):
        return
    start, end = pd.Timestamp(runs["start"].iloc[0]), pd.Timestamp(runs["end"].iloc[0])
    days = (end.normalize() - start.normalize()).days + 1
    if days < 2:
        return
    answer.facts["one_run_days"] = days
    answer.sentences.append(
        f"The log is one run of {days} days ({start:%Y-%m-%d} to {end:%Y-%m-%d}), so the "
        "pauses between its sessions count as waiting below: split it into runs "
        "(--case-gap 1h, or Split into runs when uploading it)."
    )


def trusted_first(ranking: pd.DataFrame, alpha: float = ALPHA) -> pd.DataFrame:
    """The bottleneck ranking with the rows that are not ``ranked`` (an effect that may be
    chance, has no test result or adds under 1 % of a run; or, in a table without that column,
    a p-value of ``alpha`` or more) after the others, each part still by delay per case;
    ``rank`` numbers the new order."""
    if ranking.empty:
        return ranking
    if "ranked" in ranking.columns:
        uncertain = ~ranking["ranked"].astype(bool).to_numpy()
    elif "p_value" in ranking.columns:
        uncertain = pd.to_numeric(ranking["p_value"], errors="coerce").ge(alpha).to_numpy(bool)
    else:
        return ranking
    ordered = pd.concat([ranking[~uncertain], ranking[uncertain]]).reset_index(drop=True)
    return ordered.assign(rank=range(1, len(ordered) + 1))


def _slowest_run(runs: pd.DataFrame) -> str | None:
    if runs.empty:
        return None
    return str(runs.loc[runs["duration"].idxmax(), "case"])


# -- 3. where each robot worked ----------------------------------------------------------------


def robot_answer(log: pd.DataFrame, performance: Perspective) -> Answer:
    answer = Answer("robots", "Where did each robot work, and where do robots overlap?")
    if ROBOT not in log.columns:
        answer.sentences.append("The log does not say which robot did what (no robot column).")
        return answer
    work = _robot_work(performance)
    areas = robot_areas(log)
    answer.facts["robots"] = work
    for robot in work:
        area = areas.get(robot["robot"])
        where = f" in x {_span(area['x'])}, y {_span(area['y'])}" if area else ""
        where += f", z {_span(area['z'])}" if area and "z" in area else ""
        robot["area"] = area
        answer.sentences.append(
            f"{robot['robot']} worked {seconds_text(robot['working'])} in "
            f"{_count(robot['runs'], 'run')}{where}, most of it on {robot['main_activity']}."
        )
    if X not in log.columns or Y not in log.columns:
        answer.sentences.append("The log has no positions, so where robots overlap is unknown.")
        return answer
    placed = positions(log)
    met = encounters(placed)
    overlaps = region_overlaps(run_regions(placed))
    answer.facts["encounters"] = _records(met)
    answer.facts["overlaps"] = overlaps
    answer.facts["same_place"] = {"metres": METRES, "seconds": SECONDS}
    answer.sentences += _encounter_sentences(met)
    answer.sentences.append(_overlap_sentence(overlaps, placed))
    return answer


def _records(table: pd.DataFrame) -> list[dict[str, Any]]:
    """The rows as ``to_dict("records")`` gives them, converted a column at a time (a row at
    a time boxes every value on its own)."""
    columns = [table[c].tolist() for c in table.columns]
    names = list(table.columns)
    return [dict(zip(names, values, strict=True)) for values in zip(*columns, strict=True)]


def _encounter_sentences(met: pd.DataFrame) -> list[str]:
    """Which robots were at the same place at the same moment, in 3D and time."""
    within = f"within {METRES:g} m and {SECONDS:g} s, in 3D"
    if met.empty:
        return [f"No two robots were at the same place at the same moment ({within})."]
    sentences = []
    for (robot, other), rows in met.groupby(["robot", "other"], sort=True):
        first = rows.sort_values("start", kind="stable").iloc[0]
        sentences.append(
            f"{robot} and {other} were at the same place at the same moment ({within}) "
            f"{_count(len(rows), 'time')} in {_count(rows[CASE].nunique(), 'run')}; the first "
            f"in run {first[CASE]} at {_clock(first['start'])}, at x {first[X]:.1f}, "
            f"y {first[Y]:.1f}, z {first[Z]:.1f} ({first['closest']:.1f} m apart)."
        )
    return sentences


def _overlap_sentence(overlaps: list[dict[str, Any]], placed: pd.DataFrame) -> str:
    runs = placed[CASE].nunique() if not placed.empty else 0
    if not overlaps:
        return "No two robots' regions (x, y and z, per run) overlap."
    pairs = Counter(tuple(o["robots"]) for o in overlaps)
    listed = "; ".join(f"{a} and {b} in {n} of {runs} runs" for (a, b), n in sorted(pairs.items()))
    return f"Regions (x, y and z, per run) overlap: {listed}, not necessarily at the same time."


def _robot_work(performance: Perspective) -> list[dict[str, Any]]:
    """Per robot: working seconds, runs, and the activity it spent most time on."""
    if not performance.has_data:
        return []
    robots = performance.tables["robots"]
    activities = performance.tables["activities"]
    main = activities.sort_values("total", ascending=False, kind="stable").drop_duplicates("robot")
    main = main.set_index("robot")["activity"]
    grouped = robots.groupby("robot", sort=True).agg(
        working=("working", "sum"), runs=("case", "nunique")
    )
    return [
        {
            "robot": str(robot),
            "working": float(row["working"]),
            "runs": int(row["runs"]),
            "main_activity": str(main.get(robot, "")),
        }
        for robot, row in grouped.iterrows()
    ]


def robot_areas(log: pd.DataFrame) -> dict[str, dict[str, list[float]]]:
    """Per robot, the box (x, y and, where the log has it, z ranges) its positions span."""
    if X not in log.columns or Y not in log.columns or ROBOT not in log.columns:
        return {}
    axes = [a for a in (X, Y, Z) if a in log.columns]
    placed = log[[ROBOT, *axes]].dropna(subset=[ROBOT, X, Y])
    if placed.empty:
        return {}
    box = placed.groupby(placed[ROBOT].astype(str))[axes].agg(["min", "max"])
    return {
        str(robot): {
            axis: [float(row[(axis, "min")]), float(row[(axis, "max")])]
            for axis in axes
            if pd.notna(row[(axis, "min")])
        }
        for robot, row in box.iterrows()
    }


# -- 4. battery --------------------------------------------------------------------------------


def battery_answer(battery: Perspective, runs: pd.DataFrame) -> Answer:
    answer = Answer("battery", "Did battery affect the mission?")
    if not battery.has_data:
        answer.sentences.append(_sentence(battery.message))
        return answer
    summary = battery.summary
    lows = battery.tables.get("low_battery", pd.DataFrame())
    per_run = summary.get("used_per_run") or {}
    answer.facts = {
        "low_battery_events": int(summary.get("low_battery_events", 0)),
        "used_per_run": dict(per_run),
        "most_used_by": summary.get("most_used_by"),
    }
    if per_run:
        each = ", ".join(f"{robot} {used:.1f}%" for robot, used in per_run.items())
        most = summary.get("most_used_by")
        answer.sentences.append(
            "Battery used per run from each robot's first event to its last, each robot its "
            f"own (mean): {each}" + (f"; the activity that used most: {most}." if most else ".")
        )
    if lows.empty:
        answer.sentences.append(
            f"No robot's battery ran low (below "
            f"{summary.get('threshold', LOW_BATTERY_PERCENT):g}%), so battery did not hold the "
            "mission back."
        )
        return answer
    affected = sorted(lows["case"].astype(str).unique()) if "case" in lows else []
    answer.facts["runs_with_low_battery"] = len(affected)
    # the earliest moment, not the first row: runs numbered 1..12 sort "10" before "4"
    first = lows.sort_values("time", kind="stable").iloc[0] if "time" in lows else lows.iloc[0]
    answer.sentences.append(
        f"{_count(len(lows), 'low-battery moment')} in {len(affected)} of {len(runs)} runs; "
        f"the first: {_who(first)}run {first['case']} at {_clock(first['time'])}"
        + (f", after which it did {first['then']}." if _value(first.get("then")) else ".")
    )
    answer.sentences.append(_low_battery_effect(runs, affected, answer.facts))
    answer.evidence.append(
        {"kind": "timeline", "label": f"run {first['case']}", "case": str(first["case"])}
    )
    return answer


def _who(moment: pd.Series) -> str:
    """The robot of a moment, for a sentence ('' when the log names no robot)."""
    robot = _value(moment.get("robot"))
    return f"{robot} in " if robot else ""


def _low_battery_effect(runs: pd.DataFrame, affected: list[str], facts: dict) -> str:
    """How much longer the runs with a low-battery moment took than the others (median)."""
    durations = runs.set_index(runs["case"].astype(str))["duration"]
    hit = durations[durations.index.isin(affected)]
    calm = durations[~durations.index.isin(affected)]
    if hit.empty or calm.empty:
        return "Every run had a low-battery moment, so there is no run without one to compare."
    longer = float(hit.median() - calm.median())
    facts["longer_by"] = longer
    if longer <= 0:
        return "The runs with a low-battery moment were not slower than the others (median)."
    return (
        f"Those runs took {seconds_text(longer)} longer than the others (median "
        f"{seconds_text(hit.median())} against {seconds_text(calm.median())})."
    )


# -- 5. messages -------------------------------------------------------------------------------


def message_answer(communication: Perspective) -> Answer:
    answer = Answer("messages", "Which messages were delayed, lost or resent?")
    if not communication.has_data:
        answer.sentences.append(_sentence(communication.message))
        return answer
    summary = communication.summary
    messages = communication.tables["messages"]
    keys = (
        "messages",
        "received",
        "lost",
        "unobserved",
        "delayed",
        "resends",
        "resends_new_id",
        "recovered",
    )
    answer.facts = {key: int(summary.get(key, 0)) for key in keys}
    answer.facts["untagged_types"] = list(summary.get("untagged_types", []))
    answer.facts["delay_rule"] = summary.get("delay_rule")
    unobserved = int(summary.get("unobserved", 0))
    not_seen = f", {unobserved} not observed as received" if unobserved else ""
    answer.sentences.append(
        f"{_count(summary['messages'], 'message')} sent: {summary['received']} received, "
        f"{summary['lost']} lost{not_seen}, {summary.get('delayed', 0)} delayed, "
        f"{_count(summary['resends'], 'resend')} "
        f"({summary.get('resends_new_id', 0)} under a new id)."
    )
    untagged = answer.facts["untagged_types"]
    if untagged:
        answer.sentences.append(
            f"The log tags no receive of {', '.join(untagged)}: whether those messages "
            "arrived is unknown, so none of them is called lost."
        )
    if summary.get("delay_rule"):
        answer.sentences.append(f"Delayed means {summary['delay_rule']}.")
    for kind, rows in (
        ("delayed", messages[messages["delayed"]]),
        ("lost", messages[messages["lost"]]),
        ("resent", messages[messages["resends"] > 0]),
    ):
        if not rows.empty:
            answer.sentences.append(_message_example(kind, rows.iloc[0], communication))
            answer.evidence.append(_timeline(rows.iloc[0], f"the {kind} message"))
    return answer


def _message_example(kind: str, row: pd.Series, communication: Perspective) -> str:
    where = f"{row['msg_id']} ({row['message_type']}) from {row['sender']} in run {row['case']}"
    if kind == "delayed":
        late = seconds_text(row["latency"])
        return f"Delayed, for example: {where} reached {row['receiver']} after {late}."
    if kind == "resent":
        repeated = _value(row.get("repeats"))
        how = f"repeats {repeated}, which had no answer" if repeated else "sent again under its id"
        return f"Resent, for example: {where} {how}."
    lost = communication.tables.get("lost", pd.DataFrame())
    # the lost table's row of this message (by the keys it has: a log may lack the case)
    keys = [key for key in ("case", "msg_id") if key in lost.columns and key in row.index]
    mine = lost[(lost[keys] == row[keys]).all(axis=1)] if keys else lost.iloc[:0]
    then = _value(mine["then"].iloc[0]) if "then" in mine and len(mine) else None
    followed = f"; then the sender did {then}" if then else ""
    return (
        f"Lost, for example: {where}, sent at {_clock(row['sent_at'])}{followed}"
        f"{_ended_later(mine)}."
    )


def _ended_later(lost: pd.DataFrame) -> str:
    """How much later a lost message's run ended than the median run without one."""
    if "ended_later_by" not in lost or lost.empty:
        return ""
    later = _value(lost["ended_later_by"].iloc[0])
    if later is None:
        return ""
    if later == 0:
        return "; its run took as long as the median run without a lost message"
    how = "longer" if later > 0 else "shorter"
    return f"; its run took {seconds_text(abs(later))} {how} than the median run without one"


def _timeline(row: pd.Series, label: str) -> dict[str, Any]:
    return {"kind": "timeline", "label": f"{label}, run {row['case']}", "case": str(row["case"])}


# -- wording -----------------------------------------------------------------------------------


def seconds_text(seconds: float) -> str:
    """A duration the way a person says it: 42.0s, 3.5 min, 2.1 h."""
    if seconds is None or pd.isna(seconds):
        return "an unknown time"
    seconds = float(seconds)
    if abs(seconds) < 120:
        return f"{seconds:.1f}s"
    if abs(seconds) < 7200:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def _count(number: int, noun: str) -> str:
    return f"{int(number)} {noun}{'' if int(number) == 1 else 's'}"


def _path(variant: str, limit: int = 8) -> str:
    steps = str(variant).split(ARROW)
    shown = " → ".join(steps[:limit])
    return shown + (f" … ({len(steps)} activities)" if len(steps) > limit else "")


def _span(bounds: list[float]) -> str:
    return f"{bounds[0]:.1f}–{bounds[1]:.1f}"


def _clock(time: Any) -> str:
    return pd.Timestamp(time).strftime("%Y-%m-%d %H:%M:%S") if not pd.isna(time) else "?"


def _value(value: Any) -> Any:
    """None for a missing value (NaN, NA, None, an empty string)."""
    if value is None or (pd.api.types.is_scalar(value) and pd.isna(value)):
        return None
    return None if isinstance(value, str) and not value else value


def _sentence(text: str | None) -> str:
    text = (text or "").strip()
    if not text:
        return ""
    text = text[0].upper() + text[1:]
    return text if text.endswith((".", "!", "?")) else text + "."
