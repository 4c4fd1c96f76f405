"""Random multi-robot missions: a seeded generator of a BPMN collaboration and its world.

``generate(seed, folder)`` writes ``mission.bpmn`` and ``world.yaml`` into ``folder`` and
returns the :class:`Mission` it drew. The same seed gives the same files. A mission has 2 to 6
pools, drawn from three roles:

- a **scout** (a drone): takes off and runs *Explore* over the field; for every weed its
  camera sees, Explore throws ``job`` and holds still until a worker's ``job_done`` arrives
  (``resume_on``: a skill consuming a signal without a catch event), or ``resume_after``
  seconds. An interrupting timer on Explore cuts a long exploration short; an interrupting
  event sub-process on the ``low_battery`` error flies it home;
- **workers** (ground robots, one pool each, deaf to ``job`` and ``ping`` while busy,
  ``busy_ignores``): a ``job`` starts an instance that drives to the
  weed (an interrupting timer on *GoTo* gives up), cuts (a loop or a multi-instance
  activity of random durations) and throws ``job_done`` with the weed's position; a ``ping``
  starts another that answers ``pong`` with the task number at once;
- a **coordinator** (a ground robot that stays at its base): for each of its tasks it throws
  ``ping`` and races ``pong`` against a timer, resending the same task on a timeout at most
  twice, then gives the task up; a multi-instance *Check* precedes the tasks.

Faults are drawn too: a network with jitter (delays) and losses on best-effort readers, a
worker that dies, a scout whose battery drains fast, a dropped ``job_done``, the answers of
the first seconds lost (``pong``), so that the coordinator asks again. A message's
payload names its task (a weed's position, or a coordinator's task number), so a resend is
the same sender, topic and payload as an earlier send of the run; the tests' oracle relies on
that, robotale's analysis must not.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from xml.sax.saxutils import escape, quoteattr

import yaml

from robotale.files import write_files

MODEL, WORLD = "mission.bpmn", "world.yaml"
VECTOR3 = "geometry_msgs/msg/Vector3"
#: the delay above which the generated worlds' messages count as delayed: the networks'
#: latency is 10-50 ms with jitter, and a reliable resend adds ``retry`` (0.05 s) or more
DELAY_THRESHOLD = 0.1


@dataclass
class Mission:
    """What :func:`generate` drew (the files say it all; this is for tests and tables)."""

    seed: int
    pools: list[str]
    scout: bool
    coordinator: bool
    workers: int
    faults: list[str] = field(default_factory=list)
    network: dict[str, Any] = field(default_factory=dict)
    model: Path = Path()
    world: Path = Path()


def generate(seed: int, folder: str | Path, *, time_limit: float | None = None) -> Mission:
    """Draw a mission from ``seed`` and write its model and world into ``folder``."""
    rng = random.Random(seed)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    pools = rng.randint(2, 6)
    scout = rng.random() < 0.7
    coordinator = not scout or (pools >= 3 and rng.random() < 0.5)
    workers = pools - scout - coordinator
    mission = Mission(seed, [], scout, coordinator, workers)
    field_size = rng.choice([4.0, 5.0, 6.0])
    best_effort = rng.random() < 0.5
    processes, robots, bases = [], {}, {}
    if scout:
        processes.append(_scout(rng, field_size))
        bases["scout_base"] = {"position": [0.0, field_size / 2], "radius": 0.5}
        robots["scout"] = _scout_robot(rng)
    if coordinator:
        processes.append(_coordinator(rng, workers))
        bases["coordinator_base"] = {"position": [field_size, 0.0], "radius": 0.5}
        robots["coordinator"] = _ground("coordinator_base", rng)
    for number in range(1, workers + 1):
        name = f"worker_{number}"
        processes.append(_worker(rng, name, scout, coordinator, best_effort))
        bases[f"{name}_base"] = {"position": [0.0, (number - 1) * 0.8], "radius": 0.4}
        robots[name] = _ground(f"{name}_base", rng, blade=True)
        # one task at a time: a robot's instances share its variables, so a second job
        # taken while one runs would overwrite the first one's target
        robots[name]["busy_ignores"] = ["job", "ping"]
    mission.pools = [p.name for p in processes]
    mission.network = _network(rng)
    mission.faults = _faults(rng, mission)
    world = {
        "model": MODEL,
        "field": [field_size, field_size],
        "time_limit": time_limit or rng.choice([90, 120, 150]),
        "control_rate": 5,
        "record_rate": 2,
        "start": "2024-05-16T10:00:00Z",
        "network": mission.network,
        "faults": mission.faults,
        "bases": bases,
        "robots": robots,
        "weeds": {"count": [1, 4], "margin": 0.8, "size": 0.2},
    }
    mission.model, mission.world = folder / MODEL, folder / WORLD
    write_files(
        [
            (mission.model, _definitions(processes)),
            (mission.world, yaml.safe_dump(world, sort_keys=False)),
        ]
    )
    return mission


# -- the robots and the faults -----------------------------------------------------------------


def _scout_robot(rng: random.Random) -> dict[str, Any]:
    return {
        "kind": "drone",
        "base": "scout_base",
        "max_speed": round(rng.uniform(0.6, 1.2), 2),
        "max_turn": 3.0,
        "altitude": round(rng.uniform(1.0, 3.0), 2),
        "climb": 1.0,
        "size": [0.4, 0.4, 0.1],
        "camera": {"fov": 90, "detects": "weed"},
        "start_jitter": 0.1,
        "battery": {"level": [0.6, 1.0], "drain": [0.001, 0.003], "move_drain": 0, "low": 0.2},
    }


def _ground(base: str, rng: random.Random, *, blade: bool = False) -> dict[str, Any]:
    robot = {
        "kind": "ground",
        "base": base,
        "max_speed": round(rng.uniform(0.4, 1.0), 2),
        "max_turn": 2.0,
        "size": [0.4, 0.3, 0.2],
        "start_jitter": 0.1,
        "battery": {
            "level": [0.5, 1.0],
            "drain": [0.0005, 0.001],
            "move_drain": [0.002, 0.006],
            "low": 0.1,
        },
    }
    if blade:
        robot["blade"] = True
    return robot


def _network(rng: random.Random) -> dict[str, Any]:
    return {
        "latency": round(rng.uniform(0.01, 0.05), 3),
        "jitter": round(rng.choice([0.0, 0.005, 0.03]), 3),
        "loss": round(rng.choice([0.0, 0.0, 0.1, 0.3]), 2),
        "retry": 0.05,
        "deadline": 1.0,
    }


def _faults(rng: random.Random, mission: Mission) -> list[str]:
    faults = []
    if mission.workers > 1 and rng.random() < 0.3:
        faults.append(f"die:worker_{rng.randint(1, mission.workers)}@{rng.randint(3, 30)}")
    if mission.scout and rng.random() < 0.3:
        faults.append(f"battery:scout@{rng.randint(2, 20)},rate=0.05")
    if mission.scout and rng.random() < 0.2:
        faults.append("drop:/job_done,nth=1")
    if mission.coordinator and rng.random() < 0.5:
        # the answers of the first seconds are lost: the coordinator asks again
        faults.append(f"drop:/pong@0-{rng.randint(1, 8)}")
    return faults


# -- the processes -----------------------------------------------------------------------------


class _Process:
    """One pool's process as BPMN text: elements and the flows between them."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.key = name.replace(" ", "")
        self.parts: list[str] = []
        self._flows = 0

    def id(self, local: str) -> str:
        return f"{self.key}_{local}"

    def add(self, text: str) -> None:
        self.parts.append(text)

    def flow(self, source: str, target: str, condition: str = "", *, into: list | None = None):
        self._flows += 1
        ident = self.id(f"f{self._flows}")
        body = (
            f'<bpmn:conditionExpression xsi:type="bpmn:tFormalExpression" language="python">'
            f"{escape(condition)}</bpmn:conditionExpression>"
            if condition
            else ""
        )
        (self.parts if into is None else into).append(
            f'<bpmn:sequenceFlow id="{ident}" sourceRef="{source}" targetRef="{target}">'
            f"{body}</bpmn:sequenceFlow>"
        )


def _properties(**values: str) -> str:
    items = "".join(
        f"<camunda:property name={quoteattr(k)} value={quoteattr(str(v))} />"
        for k, v in values.items()
    )
    return _extensions(f"<camunda:properties>{items}</camunda:properties>")


def _inputs(**values: Any) -> str:
    items = "".join(
        f"<camunda:inputParameter name={quoteattr(k)}>{escape(str(v))}</camunda:inputParameter>"
        for k, v in values.items()
    )
    return _extensions(f"<camunda:inputOutput>{items}</camunda:inputOutput>")


def _extensions(inner: str) -> str:
    return f"<bpmn:extensionElements>{inner}</bpmn:extensionElements>"


def _data(p: _Process, local: str, name: str, **values: str) -> str:
    """A data object setting variables from a caught message, and the association to it."""
    ident = p.id(local)
    p.add(
        f'<bpmn:dataObjectReference id="{ident}" name="{name}" dataObjectRef="{ident}_object">'
        + _properties(**values)
        + f'</bpmn:dataObjectReference><bpmn:dataObject id="{ident}_object" />'
    )
    return (
        f"<bpmn:dataOutputAssociation><bpmn:targetRef>{ident}</bpmn:targetRef>"
        "</bpmn:dataOutputAssociation>"
    )


def _call(ident: str, name: str, skill: str, inputs: str = "", loop: str = "") -> str:
    return (
        f'<bpmn:callActivity id="{ident}" name="{name}" calledElement="{skill}">'
        f"{inputs}{loop}</bpmn:callActivity>"
    )


def _signal_event(tag: str, ident: str, signal: str, extra: str = "", name: str = "") -> str:
    return (
        f'<bpmn:{tag} id="{ident}" name="{name or signal}">{extra}'
        f'<bpmn:signalEventDefinition signalRef="Signal_{signal}" /></bpmn:{tag}>'
    )


def _timer(tag: str, ident: str, seconds: float, attrs: str = "", name: str = "") -> str:
    label = name or f"wait {seconds:g} s"
    return (
        f'<bpmn:{tag} id="{ident}" name="{label}"{attrs}><bpmn:timerEventDefinition>'
        f'<bpmn:timeDuration xsi:type="bpmn:tFormalExpression">PT{seconds:g}S</bpmn:timeDuration>'
        f"</bpmn:timerEventDefinition></bpmn:{tag}>"
    )


def _scout(rng: random.Random, size: float) -> _Process:
    p = _Process("Scout")
    i = p.id
    explore = _inputs(
        x_lower_boundary=0.5,
        y_lower_boundary=0.5,
        x_upper_boundary=size - 0.5,
        y_upper_boundary=size - 0.5,
        swath=2.0,
        speed=1.0,
        signal="job",
        signal_type=VECTOR3,
        resume_on="job_done",
        resume_after=rng.choice([10, 20, 30]),
        stop_after=rng.randint(1, 3),
    )
    p.add(f'<bpmn:startEvent id="{i("start")}" />')
    p.add(_call(i("takeoff"), "Take Off", "TakeOff"))
    p.add(_call(i("explore"), "Explore", "Explore", explore))
    limit = rng.choice([8, 15, 30, 60])
    p.add(
        _timer(
            "boundaryEvent", i("limit"), limit, f' attachedToRef="{i("explore")}"', "explore limit"
        )
    )
    p.add(f'<bpmn:exclusiveGateway id="{i("merge")}" />')
    p.add(_call(i("home"), "Return to Base", "ReturnToBase"))
    p.add(_call(i("land"), "Land", "Land"))
    p.add(_signal_event("endEvent", i("end"), "all_done", _properties(type=VECTOR3)))
    p.flow(i("start"), i("takeoff"))
    p.flow(i("takeoff"), i("explore"))
    p.flow(i("explore"), i("merge"))
    p.flow(i("limit"), i("merge"))
    p.flow(i("merge"), i("home"))
    p.flow(i("home"), i("land"))
    p.flow(i("land"), i("end"))
    p.add(_battery_handler(p, land=True))
    return p


def _battery_handler(p: _Process, *, land: bool) -> str:
    """An interrupting event sub-process on the ``low_battery`` error: home (and land)."""
    i = p.id
    inner: list[str] = [
        f'<bpmn:startEvent id="{i("low_start")}" name="low_battery">'
        '<bpmn:errorEventDefinition errorRef="Error_low_battery" /></bpmn:startEvent>',
        _call(i("low_home"), "Return to Base", "ReturnToBase"),
        f'<bpmn:endEvent id="{i("low_end")}" />',
    ]
    last = i("low_home")
    p.flow(i("low_start"), i("low_home"), into=inner)
    if land:
        inner.append(_call(i("low_land"), "Land", "Land"))
        p.flow(last, i("low_land"), into=inner)
        last = i("low_land")
    p.flow(last, i("low_end"), into=inner)
    return (
        f'<bpmn:subProcess id="{i("low_battery")}" name="Battery Handler" triggeredByEvent="true">'
        + "".join(inner)
        + "</bpmn:subProcess>"
    )


def _worker(
    rng: random.Random, name: str, scout: bool, coordinator: bool, best_effort: bool
) -> _Process:
    p = _Process(name.replace("_", " ").title())
    i = p.id
    reliability = "best_effort" if best_effort else "reliable"
    if scout:
        job = {"x_target": "${x}", "y_target": "${y}", "x_job": "${x}", "y_job": "${y}"}
        out = _data(p, "job_data", "Job", **job)
        extra = _properties(type=VECTOR3, reliability=reliability) + out
        p.add(_signal_event("startEvent", i("job"), "job", extra))
        p.add(_call(i("goto"), "Go To", "GoTo", _inputs(tolerance=0.3, speed=1.0)))
        p.add(
            _timer("boundaryEvent", i("give_up"), rng.choice([4, 10, 30]),
                   f' attachedToRef="{i("goto")}"', "give up")
        )  # fmt: skip
        p.add(
            _call(
                i("cut"),
                "Cut Grass",
                "CutGrass",
                _inputs(duration=rng.choice([1, 2, 4])),
                _loop(rng),
            )
        )
        p.add(
            _signal_event(
                "endEvent", i("done"), "job_done",
                _properties(type=VECTOR3, payload='{"x": ${x_job}, "y": ${y_job}, "z": 0.0}'),
            )
        )  # fmt: skip
        p.add(f'<bpmn:endEvent id="{i("gave_up")}" />')
        p.flow(i("job"), i("goto"))
        p.flow(i("goto"), i("cut"))
        p.flow(i("cut"), i("done"))
        p.flow(i("give_up"), i("gave_up"))
    if coordinator:
        out = _data(p, "ping_data", "Ping", asked="${x}")
        extra = _properties(type=VECTOR3, reliability=reliability) + out
        p.add(_signal_event("startEvent", i("ping"), "ping", extra))
        # answered at once: a robot's instances share its variables, so an answer that waited
        # could carry the task of a later question
        p.add(
            f'<bpmn:scriptTask id="{i("think")}" name="Look Up" scriptFormat="python">'
            "<bpmn:script>answer = asked</bpmn:script></bpmn:scriptTask>"
        )
        p.add(
            _signal_event(
                "endEvent", i("pong"), "pong",
                _properties(type=VECTOR3, payload='{"x": ${asked}, "y": 0.0, "z": 0.0}'),
            )
        )  # fmt: skip
        p.flow(i("ping"), i("think"))
        p.flow(i("think"), i("pong"))
    p.add(_battery_handler(p, land=False))
    return p


def _loop(rng: random.Random) -> str:
    """A standard loop, a multi-instance marker (parallel or sequential), or none."""
    kind = rng.choice(["none", "standard", "parallel", "sequential"])
    if kind == "standard":
        return f'<bpmn:standardLoopCharacteristics loopMaximum="{rng.randint(2, 3)}" />'
    if kind == "none":
        return ""
    sequential = ' isSequential="true"' if kind == "sequential" else ""
    return (
        f"<bpmn:multiInstanceLoopCharacteristics{sequential}>"
        f"<bpmn:loopCardinality>{rng.randint(2, 3)}</bpmn:loopCardinality>"
        "</bpmn:multiInstanceLoopCharacteristics>"
    )


def _coordinator(rng: random.Random, workers: int) -> _Process:
    p = _Process("Coordinator")
    i = p.id
    tasks = rng.randint(2, 5)
    timeout = rng.choice([1.5, 3, 6])
    p.add(f'<bpmn:startEvent id="{i("start")}" />')
    p.add(
        f'<bpmn:scriptTask id="{i("check")}" name="Check" scriptFormat="python">'
        f"<bpmn:multiInstanceLoopCharacteristics><bpmn:loopCardinality>{workers}"
        "</bpmn:loopCardinality></bpmn:multiInstanceLoopCharacteristics>"
        "<bpmn:script>checked = loopCounter</bpmn:script></bpmn:scriptTask>"
    )
    p.add(
        f'<bpmn:scriptTask id="{i("plan")}" name="Plan" scriptFormat="python">'
        "<bpmn:script>task = 0\ntries = 0</bpmn:script></bpmn:scriptTask>"
    )
    p.add(f'<bpmn:exclusiveGateway id="{i("again")}" />')
    p.add(
        _signal_event(
            "intermediateThrowEvent", i("ask"), "ping",
            _properties(type=VECTOR3, payload='{"x": ${task}, "y": 0.0, "z": 0.0}'),
        )
    )  # fmt: skip
    p.add(f'<bpmn:eventBasedGateway id="{i("race")}" />')
    p.add(_signal_event("intermediateCatchEvent", i("answer"), "pong", _properties(type=VECTOR3)))
    p.add(_timer("intermediateCatchEvent", i("timeout"), timeout, name="no answer"))
    p.add(
        f'<bpmn:scriptTask id="{i("next")}" name="Next Task" scriptFormat="python">'
        "<bpmn:script>task = task + 1\ntries = 0</bpmn:script></bpmn:scriptTask>"
    )
    p.add(
        f'<bpmn:scriptTask id="{i("retry")}" name="Count Try" scriptFormat="python">'
        "<bpmn:script>tries = tries + 1</bpmn:script></bpmn:scriptTask>"
    )
    p.add(f'<bpmn:exclusiveGateway id="{i("resend")}" />')
    p.add(f'<bpmn:exclusiveGateway id="{i("more")}" />')
    p.add(_signal_event("endEvent", i("end"), "all_done", _properties(type=VECTOR3)))
    p.flow(i("start"), i("check"))
    p.flow(i("check"), i("plan"))
    p.flow(i("plan"), i("again"))
    p.flow(i("again"), i("ask"))
    p.flow(i("ask"), i("race"))
    p.flow(i("race"), i("answer"))
    p.flow(i("race"), i("timeout"))
    p.flow(i("answer"), i("next"))
    p.flow(i("timeout"), i("retry"))
    p.flow(i("retry"), i("resend"))
    p.flow(i("resend"), i("again"), "tries < 3")
    p.flow(i("resend"), i("next"), "tries >= 3")
    p.flow(i("next"), i("more"))
    p.flow(i("more"), i("again"), f"task < {tasks}")
    p.flow(i("more"), i("end"), f"task >= {tasks}")
    return p


def _definitions(processes: list[_Process]) -> str:
    participants = "".join(
        f'<bpmn:participant id="Pool_{p.key}" name="{p.name}" processRef="Process_{p.key}" />'
        for p in processes
    )
    bodies = "".join(
        f'<bpmn:process id="Process_{p.key}" name="{p.name}" isExecutable="true">'
        + "\n".join(p.parts)
        + "</bpmn:process>\n"
        for p in processes
    )
    signals = "".join(
        f'<bpmn:signal id="Signal_{s}" name="{s}" />'
        for s in ("job", "job_done", "ping", "pong", "all_done")
    )
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" '
        'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" '
        'xmlns:camunda="http://camunda.org/schema/1.0/bpmn" id="Generated" '
        'targetNamespace="http://bpmn.io/schema/bpmn">\n'
        f'<bpmn:collaboration id="Mission">{participants}</bpmn:collaboration>\n'
        f"{bodies}{signals}"
        '<bpmn:error id="Error_low_battery" name="low_battery" errorCode="low_battery" />\n'
        "</bpmn:definitions>\n"
    )
