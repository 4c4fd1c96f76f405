"""One simulated run: the world, the mission's engines and the recorder on one clock.

:func:`simulate_run` draws the run's setup from its seed, builds the pybullet world, one
engine per robot (the mission split by :mod:`robotale.fame_runtime`) and a recorder tapping
the bus, runs the clock until every engine has ended or the time limit, and writes the bag and
its manifest (``robotale-run.json``) into a folder, with the run's ground truth beside them
(``robotale-truth.jsonl``, :mod:`robotale.sim.truth`). A run that raises is recorded as
crashed, with the reason; whatever was recorded until then stays in the bag and the truth.
"""

from __future__ import annotations

import dataclasses
import datetime as dt
import math
import time
import traceback
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from robotale.fame_runtime.bus import InProcessBus, Network
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.kinds import THROWING, EventKind, Kind
from robotale.fame_runtime.labels import error_name, signal_topic
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.manifest import RunManifest, write_manifest
from robotale.fame_runtime.mission import Mission
from robotale.fame_runtime.model import Definitions
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.skills import Skill, load_skills
from robotale.fame_runtime.tags import bus_sink
from robotale.sim import faults as fault_model
from robotale.sim import scenarios
from robotale.sim.busy import BusyDeaf, ignores_of
from robotale.sim.faults import Fault, Planned
from robotale.sim.recorder import Recorder
from robotale.sim.setup import Setup, draw, run_seed
from robotale.sim.skills import SKILLS
from robotale.sim.truth import Truth
from robotale.sim.world import SimWorld, WindowClosed
from robotale.sim.worldspec import World

ENDED, TIME_LIMIT, CRASHED = "ended", "time limit", "crashed"

#: something watching a run as it goes (``simulate --live``): given the run's case, its robots
#: and its bus before the mission starts; what it gives back is called when the run has ended
Watch = Callable[[str, list[str], InProcessBus], Callable[[], None]]


@dataclass(frozen=True)
class RunPlan:
    """Everything one run needs (it crosses into a worker process, so it pickles)."""

    world: World
    index: int  # 1-based
    batch_seed: int
    scenario: str = ""
    faults: tuple[Fault, ...] = ()
    storage: str = "sqlite3"
    extra_topics: tuple[str, ...] = ()
    settings: Mapping[str, Any] = field(default_factory=dict)  # as given, for the manifest
    distro: str = "humble"  # the ROS 2 distribution whose `ros2 bag` the metadata is written for

    @property
    def case(self) -> str:
        return f"run_{self.index:04d}"

    @property
    def seed(self) -> int:
        return run_seed(self.batch_seed, self.index)

    @property
    def start(self) -> float:
        """Runs of a batch start an hour (or a time limit) apart, so no two overlap."""
        spacing = 3600.0 * max(1, math.ceil(self.world.time_limit / 3600.0))
        return self.world.start + (self.index - 1) * spacing


def skills_of(world: World) -> dict[str, Skill]:
    """The simulator's skills, and the world's own skills module over them. A building block
    of the world's library replaces the simulator's skill of its name (the thesis' own
    ``GoTo.bpmn`` runs instead of robotale's GoTo), never a skill of the world's module."""
    library = Library(world.library) if world.library else None
    simulator = {n: s for n, s in SKILLS.items() if library is None or library.find(n) is None}
    return {**simulator, **(load_skills(world.skills) if world.skills else {})}


def simulate_run(
    plan: RunPlan,
    folder: Path,
    *,
    gui: bool = False,
    pace: float | None = None,
    watch: Watch | None = None,
) -> RunManifest:
    """Simulate and record one run into ``folder`` (created), ``watch`` watching it; returns
    its manifest."""
    began = time.perf_counter()
    world, start = plan.world, plan.start
    setup = draw(world, plan.seed)
    planned = fault_model.plan(plan.faults, plan.seed)
    clock = SimClock(start, engine_cost=world.engine_cost)
    network = _network(world)
    bus = InProcessBus(
        clock,
        latency=world.latency,
        drop=fault_model.drop_rule(planned, start),
        seed=plan.seed,
        network=network,
    )
    truth = Truth(clock, plan.case, [r.name for r in setup.robots])
    truth.watch_bus(bus)
    recorder = sim = mission = watching = None
    status, reason, detail = CRASHED, "", ""
    try:
        definitions = parse(world.model)
        mission = _mission(world, definitions, setup, clock, bus, truth)
        signals, errors = model_topics(definitions)
        recorder = Recorder(
            folder,
            robots=mission.engines,
            announced=signals,
            storage=plan.storage,
            rate=world.record_rate,
            errors=errors,
            extra=plan.extra_topics,
            distro=plan.distro,
        )
        bus.tap(recorder.tap)
        if watch is not None:  # after the recorder: a tag is in the bag before it is judged
            watching = watch(plan.case, [r.name for r in setup.robots], bus)
        sim = SimWorld(
            world, setup, clock=clock, bus=bus, gui=gui, silent=skill_signals(definitions)
        )
        if network is not None:
            network.locate = sim.position
        mission.start()
        sim.start()
        _sample(truth, sim, clock, world.record_rate)
        _schedule(planned, clock, start, sim, mission, truth)
        clock.run(until=start + world.time_limit, stop_when=lambda: mission.done, pace=pace)
        status = ENDED if mission.done else TIME_LIMIT
    except WindowClosed:
        raise
    except Exception as error:  # a crashed run is reported, never hidden
        reason = f"{type(error).__name__}: {error}"
        detail = traceback.format_exc(limit=8)
    finally:
        if sim is not None and truth.sampled_at != clock.now():
            _samples(truth, sim)  # the last moments too: the run rarely ends on a tick
        truth.ended(status)
        if watching is not None:
            watching()
        if recorder is not None:
            recorder.close()
        if sim is not None:
            sim.close()
    manifest = _manifest(plan, setup, planned, clock.now(), status, reason, detail)
    manifest.update(_what_happened(mission, sim, recorder, start))
    manifest["wall_time"] = round(time.perf_counter() - began, 3)
    folder.mkdir(parents=True, exist_ok=True)
    truth.write(folder)
    write_manifest(folder, manifest)
    return manifest


def _network(world: World) -> Network | None:
    """A fresh copy of the world's network model, so this run's positions are its own."""
    return None if world.network is None else dataclasses.replace(world.network)


def _what_happened(
    mission: Mission | None, sim: SimWorld | None, recorder: Recorder | None, start: float
) -> dict[str, Any]:
    """The engines', the world's and the recorder's side of a manifest (as far as they got)."""
    facts: dict[str, Any] = {}
    if mission is not None:
        facts["failures"] = mission.failures
        facts["robots"] = {a.robot: a.robot_type for a in mission.assignments}
        facts["instances"] = {
            name: {"completed": engine.completed, "running": not engine.idle}
            for name, engine in mission.engines.items()
        }
    if sim is not None:
        facts.update(sim.report(start))
        facts.update(_counts(facts.pop("counts")))
    if recorder is not None:
        facts["topics"] = recorder.topics()
    return facts


def _mission(
    world: World, definitions: Definitions, setup: Setup, clock, bus, truth: Truth
) -> Mission:
    variables = {}
    for start in setup.robots:
        spec = next(r for r in world.robots if r.name == start.group)
        variables[start.name] = {
            **world.variables,
            **spec.variables,
            "x_base": start.home[0],
            "y_base": start.home[1],
        }
    groups = {spec.name: spec.busy_ignores for spec in world.robots}
    engines_bus = BusyDeaf(bus, ignores_of(groups, {s.name: s.group for s in setup.robots}))
    engines_bus.observer = truth.busy
    tags = bus_sink(bus)

    def living(tag) -> None:
        if tag.robot not in truth.dead:  # a dead robot's engine ends without a further tag
            tags(tag)

    mission = Mission(
        definitions,
        robots=[r.name for r in setup.robots],
        clock=clock,
        bus=engines_bus,
        skills=skills_of(world),
        library=world.library,
        tag_sink=living,
        variables=variables,
    )
    engines_bus.engines = mission.engines
    truth.watch_engines(mission.engines)
    return mission


def model_topics(definitions: Definitions) -> tuple[dict[str, str], set[str]]:
    """The signal topics of a model with their message types (a throw's type wins over a
    catch's), and the names of the errors it catches."""
    signals: dict[str, str] = {}
    errors: set[str] = set()
    for _, process in definitions.pools():
        for node in process.walk():
            if node.event_kind == EventKind.ERROR and error_name(node):
                errors.add(error_name(node))
            if node.event_kind != EventKind.SIGNAL or not signal_topic(node):
                continue
            msgtype = node.message.msgtype if node.message else ""
            throws = node.kind in THROWING
            topic = signal_topic(node)
            if msgtype and (throws or topic not in signals):
                signals[topic] = msgtype
            signals.setdefault(topic, "std_msgs/msg/Empty")
    return signals, errors


def skill_signals(definitions: Definitions) -> frozenset[str]:
    """The signals call activities ask a skill to throw (Explore's ``signal`` input)."""
    return frozenset(
        str(node.inputs["signal"]).strip("/")
        for _, process in definitions.pools()
        for node in process.walk()
        if node.kind == Kind.CALL_ACTIVITY and isinstance(node.inputs.get("signal"), str)
    )


def _sample(truth: Truth, sim: SimWorld, clock: SimClock, rate: float) -> None:
    """The robots' true poses and batteries into the truth, ``rate`` times a second."""
    period = 1.0 / rate if rate and rate > 0 else 0.5

    def tick() -> None:
        _samples(truth, sim)
        clock.call_later(period, tick)

    tick()


def _samples(truth: Truth, sim: SimWorld) -> None:
    """Every living robot's true pose and battery now."""
    for name, robot in sim.robots.items():
        if robot.alive:
            pose = robot.pose
            truth.sample(name, pose.x, pose.y, pose.z, robot.battery.level)


def _schedule(
    planned: list[Planned], clock: SimClock, start, sim: SimWorld, mission: Mission, truth: Truth
):
    for item in planned:
        fault = item.fault
        if not item.applied or item.at is None:
            continue
        if fault.kind == "die":

            def die(name: str = fault.target) -> None:
                truth.died(name)
                sim.kill(name)
                if name in mission.engines:
                    mission.engines[name].stop(safe=False)

            clock.call_at(start + item.at, die)
        elif fault.kind == "battery":
            began = start + item.at
            clock.call_at(began, lambda n=fault.target, r=fault.rate: sim.drain(n, r))
            if fault.duration is not None:
                clock.call_at(began + fault.duration, lambda n=fault.target: sim.drain(n, 0.0))


def _manifest(
    plan: RunPlan,
    setup: Setup,
    planned: list[Planned],
    now: float,
    status: str,
    reason: str,
    detail: str,
) -> RunManifest:
    world = plan.world
    manifest: RunManifest = {
        "case": plan.case,
        "scenario": plan.scenario or world.file.stem,
        "model": scenarios.describe(world.model),
        "world": scenarios.describe(world.file),
        "seed": plan.seed,
        "batch_seed": plan.batch_seed,
        "index": plan.index,
        "start": _iso(plan.start),
        "duration": round(now - plan.start, 3),
        "outcome": {"status": status, "reason": reason},
        "settings": {
            "time_limit": world.time_limit,
            "control_rate": world.control_rate,
            "record_rate": world.record_rate,
            "latency": world.latency,
            "storage": plan.storage,
            "robots": world.robot_names(),
            **_engine_cost(world),
            **plan.settings,
        },
        "faults": [p.as_dict() for p in planned],
        "setup": setup.as_dict(),
    }
    if detail:
        manifest["outcome"]["traceback"] = detail
    return manifest


def _engine_cost(world: World) -> dict[str, Any]:
    """The manifest's ``engine_cost`` setting, for worlds whose engines' work takes time."""
    cost = world.engine_cost
    return {"engine_cost": cost.as_dict()} if cost is not None and not cost.free else {}


def _counts(counts: Mapping[str, Mapping[str, int]]) -> dict[str, Any]:
    """``weeds: {total, found, cut}``, ``targets: {total, found, destroyed}``."""
    verbs = {"weeds": "cut", "targets": "destroyed"}
    return {
        kind: {"total": c["total"], "found": c["found"], verbs.get(kind, "done"): c["done"]}
        for kind, c in counts.items()
    }


def _iso(seconds: float) -> str:
    return dt.datetime.fromtimestamp(seconds, dt.UTC).isoformat().replace("+00:00", "Z")
