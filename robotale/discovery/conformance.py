"""Conformance: replay what each robot did against the process it was meant to run.

Each robot's trace in a run is its activity instances in start order (an activity started but
never completed, such as one a boundary event interrupted, counts too: it did start). The
trace is aligned with the Petri net of the robot's pool (pm4py's alignments), which names every
deviation: an activity the model did not allow at that point ("unexpected") or one the model
required that did not happen ("missing"). Where an alignment takes too long, token-based
replay gives the fitness instead (without names).
"""

from __future__ import annotations

import warnings
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import pandas as pd
from tqdm import tqdm

from robotale.discovery.bpmn_net import process_net
from robotale.discovery.graph import json_ready
from robotale.discovery.instances import START_TIMESTAMP, activity_instances
from robotale.errors import InputError, ModelError
from robotale.eventlog.schema import ACTIVITY, CASE, MSG_ROLE, ROBOT, TIMESTAMP, message_roles
from robotale.fame_runtime.library import Library, find_process
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.splitter import split

SKIP = ">>"  # pm4py's "no move" in an alignment


class RobotModel(NamedTuple):
    """The Petri net of one robot's process: pool name, net, initial and final marking."""

    pool: str
    net: Any
    initial: Any
    final: Any


@dataclass(slots=True)
class ConformanceReport:
    """Fitness per robot and per run, and the deviating activities.

    ``robots``: robot, pool, runs, fitness (mean over its runs), precision (pm4py's
    token-based ETConformance over its runs), fitting runs, method.
    ``runs``: case, robot, fitness, fits, method (alignment or token replay), deviations.
    ``deviations``: robot, activity, kind (unexpected / missing), count, runs. ``outside``:
    robot, activity, instances of the messages a robot sent or received that its process does
    not model (a skill publishing a signal), left out of the replay.
    """

    robots: pd.DataFrame
    runs: pd.DataFrame
    deviations: pd.DataFrame
    summary: dict[str, Any] = field(default_factory=dict)
    outside: pd.DataFrame = field(
        default_factory=lambda: pd.DataFrame(columns=["robot", "activity", "instances"])
    )

    @property
    def figure(self):
        import plotly.express as px  # 0.7 s to import: only a figure needs it

        return px.bar(
            self.robots, x="robot", y="fitness", range_y=[0, 1], title="Fitness per robot"
        )

    def to_dict(self) -> dict[str, Any]:
        return json_ready(
            {
                "summary": self.summary,
                "robots": self.robots.to_dict(orient="records"),
                "runs": self.runs.to_dict(orient="records"),
                "deviations": self.deviations.to_dict(orient="records"),
                "outside": self.outside.to_dict(orient="records"),
            }
        )


def robot_traces(log: pd.DataFrame) -> pd.DataFrame:
    """Every activity instance with its case and robot, in start order (the traces)."""
    instances = activity_instances(log)  # already in start order; keep it within each robot
    order = instances.sort_values([CASE, ROBOT], kind="stable").reset_index(drop=True)
    traces = order[[CASE, ROBOT, ACTIVITY, START_TIMESTAMP]]
    return traces.assign(**{MSG_ROLE: message_roles(order).to_numpy()})


def replay(
    traces: pd.DataFrame, models: dict[str, RobotModel], *, seconds_per_trace: float = 10.0
) -> ConformanceReport:
    """Align each robot's traces with its model (``models`` maps robot -> model)."""
    runs = []
    precision: dict[str, float | None] = {}
    for robot, model in tqdm(sorted(models.items()), desc="replaying robots", leave=False):
        mine = traces[traces[ROBOT] == robot]
        rows, precision[robot] = _replay_robot(robot, model, mine, seconds_per_trace)
        runs += rows
    run_table = pd.DataFrame(
        runs, columns=[CASE, ROBOT, "fitness", "fits", "method", "deviations", "_moves"]
    )
    deviations = _deviation_table(run_table)
    robots = _robot_table(run_table, models, precision)
    report = ConformanceReport(
        robots=robots,
        runs=run_table.drop(columns="_moves").rename(columns={CASE: "case"}),
        deviations=deviations,
    )
    report.summary = {
        "fitness": float(run_table["fitness"].mean()) if len(run_table) else None,
        "runs": int(run_table[CASE].nunique()) if len(run_table) else 0,
        "robots": sorted(models),
        "fitting": bool(run_table["fits"].all()) if len(run_table) else True,
    }
    return report


def _replay_robot(robot: str, model: RobotModel, traces: pd.DataFrame, seconds: float):
    # pm4py takes 2 s to import and prints a banner: only a replay loads it.
    import pm4py
    from pm4py.algo.conformance.alignments.petri_net import algorithm as alignments
    from pm4py.algo.conformance.tokenreplay import algorithm as token_replay

    if traces.empty:
        return [], None
    event_log = pm4py.convert_to_event_log(
        traces.rename(columns={START_TIMESTAMP: TIMESTAMP}).astype({CASE: str})
    )
    quiet = {"show_progress_bar": False}  # robotale shows its own progress, per robot
    limits = quiet | {alignments.Parameters.PARAM_MAX_ALIGN_TIME_TRACE: seconds}
    with warnings.catch_warnings():  # pm4py's own use of numpy.matrix, not the user's concern
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        aligned = alignments.apply(event_log, model.net, model.initial, model.final, limits)
        replayed = token_replay.apply(event_log, model.net, model.initial, model.final, quiet)
        precision = _precision(event_log, model)
    rows = []
    for trace, alignment, tokens in zip(event_log, aligned, replayed, strict=True):
        case = trace.attributes["concept:name"]
        if alignment is None or alignment.get("alignment") is None:
            fitness = float(tokens["trace_fitness"])
            rows.append(
                (case, robot, fitness, bool(tokens["trace_is_fit"]), "token replay", "", [])
            )
            continue
        moves = _deviating_moves(alignment["alignment"])
        fitness = float(alignment["fitness"])
        text = "; ".join(f"{kind} {activity}" for kind, activity in moves)
        rows.append((case, robot, fitness, not moves, "alignment", text, moves))
    return rows, precision


def _precision(event_log, model: RobotModel) -> float:
    """How little the model allows beyond what the robot did: pm4py's token-based precision
    (ETConformance), 1 when the model permits nothing the log does not show."""
    from pm4py.algo.evaluation.precision import algorithm as precision_evaluator  # pm4py: 2 s

    variant = precision_evaluator.Variants.ETCONFORMANCE_TOKEN
    quiet = {"show_progress_bar": False}
    value = precision_evaluator.apply(
        event_log, model.net, model.initial, model.final, variant=variant, parameters=quiet
    )
    return float(value)


def _deviating_moves(alignment: list[tuple[str, str | None]]) -> list[tuple[str, str]]:
    moves = []
    for log_move, model_move in alignment:
        if model_move == SKIP and log_move != SKIP:
            moves.append(("unexpected", log_move))
        elif log_move == SKIP and model_move not in (None, SKIP):
            moves.append(("missing", model_move))
    return moves


def _deviation_table(runs: pd.DataFrame) -> pd.DataFrame:
    counts: Counter[tuple[str, str, str]] = Counter()
    in_runs: dict[tuple[str, str, str], set[str]] = {}
    for _, run in runs.iterrows():
        for kind, activity in run["_moves"]:
            key = (run[ROBOT], activity, kind)
            counts[key] += 1
            in_runs.setdefault(key, set()).add(run[CASE])
    rows = [
        {"robot": r, "activity": a, "kind": k, "count": n, "runs": len(in_runs[(r, a, k)])}
        for (r, a, k), n in counts.most_common()
    ]
    return pd.DataFrame(rows, columns=["robot", "activity", "kind", "count", "runs"])


def _robot_table(
    runs: pd.DataFrame, models: dict[str, RobotModel], precision: dict[str, float | None]
) -> pd.DataFrame:
    rows = []
    for robot, model in sorted(models.items()):
        mine = runs[runs[ROBOT] == robot]
        rows.append(
            {
                "robot": robot,
                "pool": model.pool,
                "runs": len(mine),
                "fitness": float(mine["fitness"].mean()) if len(mine) else None,
                "precision": precision.get(robot),
                "fitting_runs": int(mine["fits"].sum()),
                "method": " + ".join(sorted(set(mine["method"]))),
            }
        )
    columns = ["robot", "pool", "runs", "fitness", "precision", "fitting_runs", "method"]
    return pd.DataFrame(rows, columns=columns)


def check_conformance(
    log: pd.DataFrame,
    model: str | Path,
    *,
    library: str | Path | None = None,
    seconds_per_trace: float = 10.0,
) -> ConformanceReport:
    """Replay every robot of ``log`` against its pool of the BPMN collaboration ``model``.

    Pools bind robots as the splitter binds them when the model runs (``Drone`` -> ``drone``,
    a multi-instance ``Tractor`` -> ``tractor_1``, ``tractor_2`` ...). Call activities are
    expanded when the called process is in the same file or in the ``library`` folder of
    building blocks, as the engine would run them.
    """
    if ROBOT not in log.columns:
        raise InputError("conformance needs the robot of every event; the log has no robot column.")
    definitions = parse(model)
    blocks = Library(library) if library is not None else None
    traces = robot_traces(log)
    assignments = _bind(definitions, sorted(traces[ROBOT].dropna().unique()))

    def resolve(name: str):
        return find_process(definitions, name) or (blocks.find(name) if blocks else None)

    models = {}
    for assignment in assignments:
        observed = set(traces.loc[traces[ROBOT] == assignment.robot, ACTIVITY])
        net = process_net(assignment.process, observed, resolve)
        models[assignment.robot] = RobotModel(assignment.robot_type, *net)
        _require_completable(models[assignment.robot], model)
    outside = _outside_the_models(traces, models)
    report = replay(traces[~outside], models, seconds_per_trace=seconds_per_trace)
    report.outside = (
        traces[outside].groupby([ROBOT, ACTIVITY]).size().rename("instances").reset_index()
    ).rename(columns={ACTIVITY: "activity"})
    report.summary["model"] = str(model)
    return report


def _require_completable(robot_model: RobotModel, file: str | Path) -> None:
    """Alignments need a net whose end can be reached from its start at all (pm4py: "easy
    sound"); a pool where no run can complete (an exclusive split into a parallel join, say)
    is a modelling error, named here rather than as pm4py's exception."""
    from pm4py.objects.petri_net.utils import check_soundness  # pm4py: 2 s, conformance only

    net, initial, final = robot_model.net, robot_model.initial, robot_model.final
    if not check_soundness.check_easy_soundness_net_in_fin_marking(net, initial, final):
        raise ModelError(
            f"{file}: no run of pool {robot_model.pool} can reach its end event (a join waits "
            "for a branch that never comes, or a branch never ends), so its runs cannot be "
            "aligned; `robotale fame check` shows where."
        )


def _outside_the_models(traces: pd.DataFrame, models: dict[str, RobotModel]) -> pd.Series:
    """Message instances whose label the robot's net does not have: code the process calls,
    such as a skill, sent or received them, so the process has nothing to say about them."""
    labels = {robot: {t.label for t in m.net.transitions if t.label} for robot, m in models.items()}
    known = [
        activity in labels.get(robot, ())
        for robot, activity in zip(traces[ROBOT], traces[ACTIVITY], strict=True)
    ]
    return traces[MSG_ROLE].notna() & ~pd.Series(known, index=traces.index)


def _bind(definitions, robots: list[str]) -> list:
    try:
        return split(definitions, robots)
    except ModelError as error:
        raise InputError(f"{error}; the log's robots are {', '.join(robots)}.") from error
