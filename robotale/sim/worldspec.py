"""The world file: where things are, which robots exist, what varies from run to run.

A world is a YAML file next to its mission model (see ``docs/sim.md`` for every key)::

    model: agri.bpmn
    field: [10, 10]
    bases:
      drone_base: {position: [-1, 5]}
    robots:
      drone: {kind: drone, base: drone_base}
      tractor: {kind: ground, base: tractor_base, count: 2, blade: true}
    weeds: {count: [3, 6]}

:func:`load_world` reads and checks it; every mistake is one :class:`InputError` naming the
file and the key. Numbers that vary between runs are written ``[low, high]`` and drawn
uniformly per run.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

from robotale.errors import InputError
from robotale.fame_runtime.bus import Link, Network
from robotale.fame_runtime.clock import EngineCost
from robotale.sim.yamlcheck import Range, YamlChecker, load_yaml
from robotale.thresholds import LOW_BATTERY_PERCENT

KINDS = ("drone", "ground")
DEFAULT_START = "2024-05-16T10:00:00Z"


@dataclass(frozen=True)
class BatterySpec:
    level: Range = (1.0, 1.0)  # charge at the start, 0-1
    drain: Range = (0.0005, 0.0005)  # per second, always
    move_drain: Range = (0.001, 0.001)  # per second at 1 m/s
    flight_drain: Range = (0.0, 0.0)  # per second more while a drone is airborne
    charge: float = 0.02  # per second while resting on a charging base
    low: float = LOW_BATTERY_PERCENT / 100  # low_battery below this (a fraction)
    warn_period: float = 10.0  # low_battery repeats this often while low


@dataclass(frozen=True)
class CameraSpec:
    fov: float = 90.0  # degrees, a square footprint under the robot
    detects: str = "weed"
    # a global signal the robot's detector publishes once per new object (``weed_found``),
    # as the thesis' drone does, unless a skill of the mission throws that signal itself
    signal: str = ""
    detection: float = 1.0  # probability an object in view is detected, per frame, at 0 m
    falloff: float = 0.0  # less probability per metre between the camera and the object
    false_positives: float = 0.0  # phantom detections per second, anywhere in view


@dataclass(frozen=True)
class RangeSpec:
    max_range: float = 2.0
    cone: float = 20.0  # half angle in degrees (an ultrasonic beam)
    rays: int = 7
    direction: str = "forward"  # forward | down
    detects: str = ""  # an object kind the sensor reports on the detection topic
    detect_distance: float = 1.5
    noise: float = 0.0  # metres, standard deviation of a reading
    dropout: float = 0.0  # probability a reading is lost (reported as max_range)


@dataclass(frozen=True)
class RobotSpec:
    name: str  # the namespace, or the base of ``<name>_<n>`` when count is given
    kind: str
    base: str
    count: int | None = None
    max_speed: float = 0.5
    max_turn: float = 1.5  # rad/s
    altitude: float = 1.5  # drones fly here
    climb: float = 0.75  # drones take off and land at this vertical speed (m/s)
    size: tuple[float, float, float] = (0.6, 0.4, 0.3)
    color: tuple[float, float, float, float] = (0.8, 0.1, 0.1, 1.0)
    blade: bool = False
    blade_radius: float = 0.5
    # dynamics mode only (robotale.sim.dynamics): the body and its drive
    mass: float = 20.0  # kg
    max_force: float = 40.0  # N, the motors' forward force limit (braking too)
    max_torque: float = 10.0  # N m, the yaw torque limit
    friction: float = 0.8  # tyre grip: no more force than friction * mass * g
    drag: float = 0.0  # drones: N of air drag per (m/s)^2 (their thrust limit is max_force)
    led: bool = False
    camera: CameraSpec | None = None
    range: RangeSpec | None = None
    battery: BatterySpec = field(default_factory=BatterySpec)
    odom_drift: float = 0.0  # metres of odometry error per square root of metre travelled
    spacing: tuple[float, float] = (0.0, 1.0)  # start offset between instances of a group
    start_jitter: float = 0.0  # metres, drawn per run
    variables: Mapping[str, Any] = field(default_factory=dict)
    # signals its start events do not hear while an instance of its process runs
    busy_ignores: tuple[str, ...] = ()

    def names(self) -> list[str]:
        if self.count is None:
            return [self.name]
        return [f"{self.name}_{n}" for n in range(1, self.count + 1)]


@dataclass(frozen=True)
class BaseSpec:
    name: str
    position: tuple[float, float]
    radius: float = 0.75
    charging: bool = True
    color: tuple[float, float, float, float] = (0.2, 0.4, 0.9, 0.6)


@dataclass(frozen=True)
class ObjectsSpec:
    """Weeds or targets: how many, where (an area, default the field), how big."""

    kind: str
    count: tuple[int, int] = (0, 0)
    area: tuple[Range, Range] | None = None
    margin: float = 0.5
    size: float = 0.2
    color: tuple[float, float, float, float] = (0.1, 0.7, 0.1, 1.0)


@dataclass(frozen=True)
class ObstacleSpec:
    """A fixed box robots collide with (in dynamics mode)."""

    name: str
    position: tuple[float, float]
    size: tuple[float, float, float] = (1.0, 1.0, 0.5)
    yaw: float = 0.0  # degrees
    color: tuple[float, float, float, float] = (0.4, 0.4, 0.4, 1.0)


@dataclass(frozen=True)
class World:
    file: Path
    model: Path
    field: tuple[float, float]
    bases: Mapping[str, BaseSpec]
    robots: tuple[RobotSpec, ...]
    objects: tuple[ObjectsSpec, ...] = ()
    time_limit: float = 900.0
    control_rate: float = 10.0
    record_rate: float = 2.0
    latency: float = 0.01
    dynamics: bool = False  # ground robots with mass, forces and collisions (else kinematic)
    physics_rate: float = 120.0  # physics steps a second in dynamics mode
    obstacles: tuple[ObstacleSpec, ...] = ()
    network: Network | None = None  # None: every message arrives after ``latency``
    start: float = dt.datetime.fromisoformat(DEFAULT_START).timestamp()
    variables: Mapping[str, Any] = field(default_factory=dict)
    faults: tuple[str, ...] = ()
    library: Path | None = None  # a folder of .bpmn building blocks
    skills: str | None = None  # a Python module (or .py file) with more SKILLS
    engine_cost: EngineCost | None = None  # simulated time the engines' work takes (None: none)

    def robot_names(self) -> list[str]:
        return [name for robot in self.robots for name in robot.names()]

    def with_counts(self, counts: Mapping[str, int]) -> World:
        """The world with ``<group>: n`` robots for groups that have a count."""
        groups = {r.name: r for r in self.robots if r.count is not None}
        for group, count in counts.items():
            if group not in groups:
                known = ", ".join(sorted(groups)) or "none"
                raise InputError(
                    f"{self.file}: there is no robot group {group!r} to count (groups: {known})"
                )
            if count < 1:
                raise InputError(f"{self.file}: robot group {group!r} needs at least 1 robot")
        robots = tuple(
            replace(r, count=counts[r.name]) if r.name in counts else r for r in self.robots
        )
        return replace(self, robots=robots)


def load_world(path: str | Path, model: str | Path | None = None) -> World:
    """Read and check a world file; ``model`` overrides the file's ``model`` key."""
    path = Path(path)
    data = load_yaml(path, "the world file")
    reader = _Reader(path)
    return reader.world(reader.mapping(data, "the file"), model)


class _Reader(YamlChecker):
    """Checks one world file; every error names the file and the key."""

    def world(self, data: Mapping[str, Any], model_override: str | Path | None) -> World:
        self.known(data, "the file", _WORLD_KEYS)
        model = model_override or data.get("model")
        if not model:
            raise self.fail("the file", "names no mission model (key 'model')")
        model_path = Path(model) if model_override else self.path.parent / str(model)
        bases = {
            name: self.base(name, self.mapping(spec, f"bases.{name}"))
            for name, spec in self.mapping(data.get("bases", {}), "bases").items()
        }
        robots = tuple(
            self.robot(name, self.mapping(spec, f"robots.{name}"), bases)
            for name, spec in self.mapping(data.get("robots"), "robots").items()
        )
        if not robots:
            raise self.fail("robots", "lists no robot")
        objects = tuple(
            self.objects(kind, self.mapping(data[kind], kind))
            for kind in ("weeds", "targets")
            if data.get(kind) is not None
        )
        return World(
            file=self.path,
            model=model_path,
            field=self.pair(data.get("field", [10.0, 10.0]), "field", positive=True),
            bases=bases,
            robots=robots,
            objects=objects,
            time_limit=self.number(data.get("time_limit", 900.0), "time_limit", positive=True),
            control_rate=self.number(data.get("control_rate", 10.0), "control_rate", True),
            record_rate=self.number(data.get("record_rate", 2.0), "record_rate", positive=True),
            latency=self.number(data.get("latency", 0.01), "latency"),
            dynamics=self.flag(data.get("dynamics", False), "dynamics"),
            physics_rate=self.number(data.get("physics_rate", 120.0), "physics_rate", True),
            network=self.network(data.get("network")),
            obstacles=tuple(
                self.obstacle(name, self.mapping(spec, f"obstacles.{name}"))
                for name, spec in self.mapping(data.get("obstacles", {}), "obstacles").items()
            ),
            start=self.start(data.get("start", DEFAULT_START)),
            variables=self.mapping(data.get("variables", {}), "variables"),
            faults=tuple(str(f) for f in self.sequence(data.get("faults", []), "faults")),
            library=self.folder(data.get("library"), "library"),
            skills=self.skills(data.get("skills")),
            engine_cost=self.engine_cost(data.get("engine_cost")),
        )

    def engine_cost(self, value: Any) -> EngineCost | None:
        """``engine_cost: {script, condition, step}`` in seconds, or ``{measured: factor}``."""
        if value is None:
            return None
        data = self.mapping(value, "engine_cost")
        self.known(data, "engine_cost", set(EngineCost.__dataclass_fields__))
        costs = {key: self.number(data[key], f"engine_cost.{key}") for key in data}
        if costs.get("measured") and len(costs) > 1:
            raise self.fail("engine_cost", "is either measured or fixed costs, not both")
        return EngineCost(**costs)

    def folder(self, value: Any, where: str) -> Path | None:
        if value is None:
            return None
        path = self.path.parent / str(value)
        if not path.is_dir():
            raise self.fail(where, f"names {value!r}, which is not a folder")
        return path

    def skills(self, value: Any) -> str | None:
        if value is None:
            return None
        text = str(value)
        local = self.path.parent / text
        return str(local) if text.endswith(".py") and local.is_file() else text

    def network(self, value: Any) -> Network | None:
        """``network: {latency, jitter, loss, ..., links: {"a -> b": {...}}}``: the default
        link, and links between named robots that differ from it."""
        if value is None:
            return None
        data = dict(self.mapping(value, "network"))
        links = self.mapping(data.pop("links", {}), "network.links")
        default = self.link(data, "network", Link())
        pairs = {}
        for key, spec in links.items():
            ends = [end.strip() for end in str(key).split("->")]
            if len(ends) != 2 or not all(ends):
                raise self.fail(f"network.links.{key}", "must be written 'sender -> receiver'")
            where = f"network.links.{key}"
            pairs[(ends[0], ends[1])] = self.link(self.mapping(spec, where), where, default)
        return Network(default, pairs)

    def link(self, data: Mapping[str, Any], where: str, defaults: Link) -> Link:
        fields = Link.__dataclass_fields__
        self.known(data, where, set(fields))
        values = {
            key: self.number(data.get(key, getattr(defaults, key)), f"{where}.{key}")
            for key in fields
        }
        for key in ("loss", "loss_per_metre"):
            if values[key] > 1:
                raise self.fail(f"{where}.{key}", f"is {values[key]!r}; it must be at most 1")
        return Link(**values)

    def obstacle(self, name: str, data: Mapping[str, Any]) -> ObstacleSpec:
        where = f"obstacles.{name}"
        self.known(data, where, _OBSTACLE_KEYS)
        size = self.triple(data.get("size", ObstacleSpec.size), f"{where}.size")
        if min(size) <= 0:
            raise self.fail(f"{where}.size", f"is {list(size)!r}; all three must be positive")
        return ObstacleSpec(
            name=name,
            position=self.pair(data.get("position"), f"{where}.position"),
            size=size,
            yaw=float(self.numbers([data.get("yaw", 0.0)], f"{where}.yaw", 1)[0]),
            color=self.color(data.get("color", ObstacleSpec.color), f"{where}.color"),
        )

    def base(self, name: str, data: Mapping[str, Any]) -> BaseSpec:
        where = f"bases.{name}"
        self.known(data, where, _BASE_KEYS)
        return BaseSpec(
            name=name,
            position=self.pair(data.get("position"), f"{where}.position"),
            radius=self.number(data.get("radius", 0.75), f"{where}.radius", positive=True),
            charging=bool(data.get("charging", True)),
            color=self.color(data.get("color", BaseSpec.color), f"{where}.color"),
        )

    def robot(self, name: str, data: Mapping[str, Any], bases: Mapping[str, BaseSpec]):
        where = f"robots.{name}"
        self.known(data, where, _ROBOT_KEYS)
        kind = data.get("kind")
        if kind not in KINDS:
            raise self.fail(f"{where}.kind", f"is {kind!r}; it must be one of {', '.join(KINDS)}")
        base = data.get("base")
        if base not in bases:
            raise self.fail(
                f"{where}.base", f"is {base!r}, which is not one of the bases ({', '.join(bases)})"
            )
        count = data.get("count")
        if count is not None and (not isinstance(count, int) or count < 1):
            raise self.fail(f"{where}.count", f"is {count!r}; it must be a whole number >= 1")
        defaults = RobotSpec(name, kind, base)
        numbers = {
            key: self.number(data.get(key, getattr(defaults, key)), f"{where}.{key}", True)
            for key in (
                "max_speed",
                "max_turn",
                "altitude",
                "climb",
                "blade_radius",
                "mass",
                "max_force",
                "max_torque",
                "friction",
            )
        }
        numbers["drag"] = self.number(data.get("drag", defaults.drag), f"{where}.drag")
        return RobotSpec(
            name=name,
            kind=kind,
            base=base,
            count=count,
            size=self.triple(data.get("size", defaults.size), f"{where}.size"),
            color=self.color(data.get("color", defaults.color), f"{where}.color"),
            blade=bool(data.get("blade", False)),
            led=bool(data.get("led", False)),
            camera=self.camera(data.get("camera"), f"{where}.camera"),
            range=self.range_sensor(data.get("range"), f"{where}.range"),
            battery=self.battery(self.mapping(data.get("battery", {}), f"{where}.battery"), where),
            spacing=self.pair(data.get("spacing", defaults.spacing), f"{where}.spacing"),
            start_jitter=self.number(data.get("start_jitter", 0.0), f"{where}.start_jitter"),
            odom_drift=self.number(data.get("odom_drift", 0.0), f"{where}.odom_drift"),
            variables=self.mapping(data.get("variables", {}), f"{where}.variables"),
            busy_ignores=self.signals(data.get("busy_ignores", []), f"{where}.busy_ignores"),
            **numbers,
        )

    def camera(self, data: Any, where: str) -> CameraSpec | None:
        if data is None:
            return None
        data = self.mapping(data, where)
        self.known(data, where, _keys(CameraSpec))
        return CameraSpec(
            fov=self.number(data.get("fov", 90.0), f"{where}.fov", positive=True),
            detects=str(data.get("detects", "weed")),
            signal=str(data.get("signal") or "").strip("/"),
            detection=self.probability(data.get("detection", 1.0), f"{where}.detection"),
            falloff=self.number(data.get("falloff", 0.0), f"{where}.falloff"),
            false_positives=self.number(
                data.get("false_positives", 0.0), f"{where}.false_positives"
            ),
        )

    def range_sensor(self, data: Any, where: str) -> RangeSpec | None:
        if data is None:
            return None
        data = self.mapping(data, where)
        self.known(data, where, _keys(RangeSpec))
        direction = data.get("direction", "forward")
        if direction not in ("forward", "down"):
            raise self.fail(f"{where}.direction", f"is {direction!r}; use forward or down")
        rays = data.get("rays", 7)
        if not isinstance(rays, int) or rays < 1:
            raise self.fail(f"{where}.rays", f"is {rays!r}; it must be a whole number >= 1")
        return RangeSpec(
            max_range=self.number(data.get("max_range", 2.0), f"{where}.max_range", True),
            cone=self.number(data.get("cone", 20.0), f"{where}.cone"),
            rays=rays,
            direction=direction,
            detects=str(data.get("detects", "")),
            detect_distance=self.number(
                data.get("detect_distance", 1.5), f"{where}.detect_distance", True
            ),
            noise=self.number(data.get("noise", 0.0), f"{where}.noise"),
            dropout=self.probability(data.get("dropout", 0.0), f"{where}.dropout"),
        )

    def battery(self, data: Mapping[str, Any], robot: str) -> BatterySpec:
        where = f"{robot}.battery"
        self.known(data, where, _keys(BatterySpec))
        defaults = BatterySpec()
        level = self.range(data.get("level", defaults.level), f"{where}.level")
        if not 0 <= level[0] <= level[1] <= 1:
            raise self.fail(f"{where}.level", "must lie between 0 and 1")
        return BatterySpec(
            level=level,
            drain=self.range(data.get("drain", defaults.drain), f"{where}.drain"),
            move_drain=self.range(
                data.get("move_drain", defaults.move_drain), f"{where}.move_drain"
            ),
            flight_drain=self.range(
                data.get("flight_drain", defaults.flight_drain), f"{where}.flight_drain"
            ),
            charge=self.number(data.get("charge", defaults.charge), f"{where}.charge"),
            low=self.number(data.get("low", defaults.low), f"{where}.low"),
            warn_period=self.number(
                data.get("warn_period", defaults.warn_period), f"{where}.warn_period", True
            ),
        )

    def objects(self, kind: str, data: Mapping[str, Any]) -> ObjectsSpec:
        self.known(data, kind, _OBJECTS_KEYS)
        low, high = self.range(data.get("count", 0), f"{kind}.count")
        if low < 0 or low != int(low) or high != int(high):
            raise self.fail(f"{kind}.count", "must be a whole number or [low, high]")
        return ObjectsSpec(
            kind=kind.rstrip("s"),
            count=(int(low), int(high)),
            area=self.area(data.get("area"), f"{kind}.area"),
            margin=self.number(data.get("margin", 0.5), f"{kind}.margin"),
            size=self.number(data.get("size", 0.2), f"{kind}.size", positive=True),
            color=self.color(data.get("color", ObjectsSpec.color), f"{kind}.color"),
        )

    def area(self, value: Any, where: str) -> tuple[Range, Range] | None:
        if value is None:
            return None
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(where, "must be [[x_low, x_high], [y_low, y_high]]")
        return (self.range(value[0], f"{where}[0]"), self.range(value[1], f"{where}[1]"))

    def start(self, value: Any) -> float:
        if isinstance(value, dt.datetime):
            moment = value
        else:
            try:
                moment = dt.datetime.fromisoformat(str(value).replace("Z", "+00:00"))
            except ValueError:
                raise self.fail("start", f"{value!r} is not an ISO 8601 date-time") from None
        if moment.tzinfo is None:
            moment = moment.replace(tzinfo=dt.UTC)
        return moment.timestamp()


def _keys(spec: type, *, without: Iterable[str] = (), plus: Iterable[str] = ()) -> set[str]:
    """The keys a part of the file may have: the fields of the dataclass it becomes."""
    left_out = set(without)
    return {f.name for f in fields(spec) if f.name not in left_out} | set(plus)


#: the file's own keys: the world's fields but those it is given (its file, the objects, which
#: are written as weeds and targets)
_WORLD_KEYS = _keys(World, without={"file", "objects"}, plus={"weeds", "targets"})
_ROBOT_KEYS = _keys(RobotSpec, without={"name"})
_OBSTACLE_KEYS = _keys(ObstacleSpec, without={"name"})
_BASE_KEYS = _keys(BaseSpec, without={"name"})
_OBJECTS_KEYS = _keys(ObjectsSpec, without={"kind"})
