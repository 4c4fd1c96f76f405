"""Discover the robots' collaboration: a BPMN pool per robot type, signals, event handlers.

What the robots did becomes the model FAME would have them run (thesis 4.1.1, G1-G4):

- **pools** (G1): one per robot type; several robots of one type share a multi-instance
  pool (G1.2). Each pool's process is mined with pm4py's inductive miner from the traces of
  that type's robots (a robot's activity instances in a run, in start order). The inductive
  miner returns a process tree, block-structured by construction, so the BPMN made from it is
  sound (every run can complete, no dead parts) and, without a noise threshold, replays every
  trace it was mined from;
- **signals** (G3): a message activity (``weed_position!`` sent, ``weed_position?``
  received) is an intermediate throw or catch event of the signal of its type, where the
  traces have it; a type sent and never received is said so in its documentation;
- **event handlers** (G2.2, G4): an activity after which a robot abandons what it was doing
  is a trigger, and what the robot did next the event sub-process it starts (see
  :func:`triggers`). A received message triggers a signal start event, anything else an error
  start event (FAME's ``low_battery``). The sub-process is interrupting when the robot never
  went back to its process after it, non-interrupting when it did.
"""

from __future__ import annotations

import itertools
from collections import Counter, defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import pandas as pd

from robotale.discovery.answers import answered, as_units, expanded
from robotale.discovery.filters import LogFilter, filter_log
from robotale.discovery.instances import (
    DURATION,
    FINISHED,
    INSTANCE_KEYS,
    START_TIMESTAMP,
    activity_instances,
    interrupted,
    sort_codes,
)
from robotale.discovery.layout import Block, Tau, from_process_tree
from robotale.discovery.payload_choices import Caught, payload_fields, windows
from robotale.errors import InputError
from robotale.eventlog.prepare import robot_type
from robotale.eventlog.schema import (
    ACTIVITY,
    CASE,
    LIFECYCLE,
    MSG_PAYLOAD,
    MSG_ROLE,
    RECEIVE,
    REQUIRED,
    ROBOT,
    ROBOT_TYPE,
    SEND,
    STATE,
    TIMESTAMP,
    message_roles,
)
from robotale.fame_runtime.labels import RECEIVE as CAUGHT
from robotale.fame_runtime.labels import SEND as THROWN

#: instances of one robot this close (seconds) to an interruption happened at its moment
SAME_MOMENT = 0.5
TRIGGER_KIND = Literal["signal", "error"]


@dataclass(slots=True)
class ActivityStats:
    """How often an activity (or message) happened in a pool, and how long it took."""

    count: int
    robots: list[str]
    mean: float | None
    median: float | None
    role: str | None = None  # send / receive / None

    def text(self) -> str:
        robots = ", ".join(self.robots)
        if self.mean is None:
            return f"{self.count} times by {robots}"
        return (
            f"{self.count} times by {robots}; duration mean {self.mean:.3f} s, "
            f"median {self.median:.3f} s"
        )


@dataclass(slots=True)
class Handler:
    """An event sub-process: its trigger, what it does, how often it ran."""

    trigger: str  # the activity label that triggers it (``low_battery``, ``recall?``)
    kind: TRIGGER_KIND
    interrupting: bool
    block: Block
    count: int
    abandoned: dict[str, int] = field(default_factory=dict)  # activity -> times cut short
    #: what the engine tagged the sub-process itself with, when the log has it
    tag: str | None = None

    @property
    def name(self) -> str:
        return self.trigger.rstrip(THROWN + CAUGHT)

    def text(self) -> str:
        cut = ", ".join(f"{a} ({n}x)" for a, n in sorted(self.abandoned.items()))
        went_on = "never went back to its process" if self.interrupting else "went on after"
        shown = f"; it cut short {cut}" if cut else ""
        return f"triggered {self.count} times; the robot {went_on}{shown}"


@dataclass(slots=True)
class Pool:
    name: str  # the robot type
    robots: list[str]
    block: Block
    handlers: list[Handler]
    stats: dict[str, ActivityStats]
    traces: int
    #: the signal whose every receipt starts an instance (``None``: one instance per run)
    starts_on: str | None = None
    #: each message the process catches with a payload: every catch, what came after it
    caught: dict[str, list[Caught]] = field(default_factory=dict)

    @property
    def multi_instance(self) -> bool:
        return len(self.robots) > 1


@dataclass(slots=True)
class Signal:
    name: str
    sent: int
    received: int
    senders: list[str]  # pools
    receivers: list[str]

    def text(self) -> str:
        if not self.received:
            return f"sent {self.sent} times by {', '.join(self.senders)}; never received"
        if not self.sent:
            receivers = ", ".join(self.receivers)
            return f"received {self.received} times by {receivers}; sent by no robot of the log"
        return (
            f"sent {self.sent} times by {', '.join(self.senders)}, received {self.received} "
            f"times by {', '.join(self.receivers)}"
        )


@dataclass(slots=True)
class Collaboration:
    pools: list[Pool]
    signals: dict[str, Signal]
    info: dict[str, object] = field(default_factory=dict)

    def pool(self, name: str) -> Pool:
        return next(p for p in self.pools if p.name == name)


# -- traces ------------------------------------------------------------------------------------


def typed_instances(log: pd.DataFrame, *, by_type: bool = False) -> pd.DataFrame:
    """Every activity instance with its robot's type and message role, in the order of the
    robots' traces (case, robot, start); ``by_type``: each robot type's instances together
    first (the types in the order they first come), so a type's are one slice of rows."""
    missing = [c for c in (*REQUIRED, ROBOT) if c not in log.columns]
    if missing:
        raise InputError(
            f"discovering a collaboration needs the {', '.join(missing)} of every event; "
            "the log has no such column."
        )
    instances = activity_instances(log)
    instances = instances[instances[ROBOT].notna()]
    if instances.empty:
        raise InputError("the selected events contain no activity of a robot.")
    robots = instances[ROBOT].astype(str)
    instances = instances.assign(**{ROBOT: robots, ROBOT_TYPE: _types(instances, robots)})
    instances["_role"] = _roles(instances)
    instances["_aborted"] = interrupted(instances).to_numpy()
    # by case and robot, as a stable sort of the two columns orders them
    keys = [sort_codes(instances[ROBOT]), sort_codes(instances[CASE])]
    if by_type:  # the rows split as a group-by in first-come order would, in one take
        keys.append(pd.factorize(instances[ROBOT_TYPE])[0])
    return instances.take(np.lexsort(keys)).reset_index(drop=True)


def _types(instances: pd.DataFrame, robots: pd.Series) -> pd.Series:
    """Each instance's robot type: the log's, else named from the robot (a name's type worked
    out once per robot, and only when some instance lacks one)."""
    given = instances[ROBOT_TYPE].astype("string") if ROBOT_TYPE in instances.columns else None
    if given is not None and not given.isna().any():
        return given.astype(str)
    codes, names = pd.factorize(robots)
    typed = np.array([robot_type(name) for name in names], dtype=object)
    named = pd.Series(typed[codes], index=robots.index)
    return (named if given is None else given.fillna(named)).astype(str)


def _roles(instances: pd.DataFrame) -> pd.Series:
    """Each instance's message role as most instances of its activity have it: a log may
    mark a step next to a message with the message's role (the thesis' log marks one of
    ``select_closest_tractor``'s two starts as sending ``closest_tractor``). A tie goes to
    the role first in name order (no role first of all), as pandas' ``mode`` has it; counted
    from integer codes, not a group-by per activity, and each distinct activity's name read
    once."""
    label_codes, labels = pd.factorize(instances[ACTIVITY], use_na_sentinel=False)
    names = np.array(sorted(["", SEND, RECEIVE]), dtype=object)
    code_of = {name: code for code, name in enumerate(names)}
    named = message_roles(pd.DataFrame({ACTIVITY: labels}))
    role_codes = np.array([code_of[role or ""] for role in named], dtype=np.int64)[label_codes]
    if MSG_ROLE in instances.columns:
        # a role the log sets wins over the name's (as :func:`message_roles` has it)
        given_codes, given = pd.factorize(instances[MSG_ROLE].astype("string").fillna(""))
        for role in (SEND, RECEIVE):
            role_codes[np.isin(given_codes, np.flatnonzero(np.asarray(given) == role))] = code_of[
                role
            ]
    counts = np.bincount(
        label_codes * len(names) + role_codes, minlength=len(labels) * len(names)
    ).reshape(len(labels), len(names))
    # no role is missing: set per distinct activity, not replaced over the rows
    shown = np.array([name or None for name in names], dtype=object)
    majority = shown[counts.argmax(axis=1)]
    return pd.Series(majority[label_codes], index=instances.index, dtype=str)


def triggers(instances: pd.DataFrame, traces: Traces, *, records_aborts: bool) -> set[str]:
    """The activities of one robot type that interrupt what the robot was doing.

    Where the log records interruptions (an instance ending ``ate_abort``, aborted or
    cancelled), the trigger of each is the robot's instance that started at that moment
    (within :data:`SAME_MOMENT`), the shortest of them: the event rather than the handler
    the engine tags at the same instant. Where the log records none at all (the thesis' log),
    an activity is a trigger when it comes at most once in a trace, never first, not sent,
    and cuts in: the activity just before it is followed by it in less than half of its
    occurrences, so it happens between steps rather than as one; unless another such
    activity comes both just before and just after it in the log: the two are done side by
    side (a parallel block), not one interrupting the other.
    """
    aborted = instances[instances["_aborted"]]
    if records_aborts:
        return _recorded_triggers(instances, aborted) if not aborted.empty else set()
    return _behaving_triggers(traces)


def _recorded_triggers(instances: pd.DataFrame, aborted: pd.DataFrame) -> set[str]:
    found = set()
    by_robot = {key: group for key, group in instances.groupby([CASE, ROBOT], sort=False)}
    for index, row in aborted.iterrows():
        mine = by_robot[(row[CASE], row[ROBOT])]
        gap = (mine[START_TIMESTAMP] - row[TIMESTAMP]).dt.total_seconds().abs()
        near = mine[(gap <= SAME_MOMENT) & (mine.index != index) & ~mine["_aborted"]]
        near = near[near["_role"] != SEND]
        if near.empty:
            continue
        order = np.lexsort((near[DURATION].fillna(np.inf).to_numpy(), gap[near.index].to_numpy()))
        found.add(str(near[ACTIVITY].iloc[order[0]]))
    return found


@dataclass(slots=True)
class Traces:
    """A type's traces (case and robot) as plain lists, built once for the trigger search
    and the split: labels, message roles and whether each instance ended interrupted,
    position by position; the start and end times of all instances in one array each, trace
    ``i`` at ``offsets[i]:offsets[i + 1]`` (only the split reads them, where a trigger is)."""

    labels: list[list[str]]
    roles: list[list[str | None]]
    aborted: list[list[bool]]
    starts: np.ndarray
    ends: np.ndarray
    offsets: list[int]
    #: each received instance's payload fields (:func:`payload_fields`), position by
    #: position; ``None`` when the log has no payload of a received message
    payloads: list[list[tuple[tuple[str, str], ...]]] | None = None
    robots: list[str] = field(default_factory=list)  # each trace's robot

    def times(self, number: int) -> tuple[np.ndarray, np.ndarray]:
        """Trace ``number``'s start and end times."""
        part = slice(self.offsets[number], self.offsets[number + 1])
        return self.starts[part], self.ends[part]


def per_trace(instances: pd.DataFrame) -> Traces:
    """The instances (in trace order) cut into traces in one pass over integer codes, each
    column turned into one list and sliced (not an array per trace)."""
    if instances.empty:
        return Traces([], [], [], np.array([]), np.array([]), [0])
    cases = pd.factorize(instances[CASE])[0]
    robots = pd.factorize(instances[ROBOT])[0]
    bounds = np.flatnonzero((cases[1:] != cases[:-1]) | (robots[1:] != robots[:-1])) + 1
    offsets = [0, *bounds.tolist(), len(instances)]

    def cut(values: np.ndarray) -> list[list]:
        whole = values.tolist()
        return [whole[begin:end] for begin, end in itertools.pairwise(offsets)]

    # an instance that never ended runs on past everything after it
    until = instances[TIMESTAMP].where(instances[FINISHED].astype(bool))
    fields = _received_payloads(instances)
    return Traces(
        labels=cut(instances[ACTIVITY].astype(str).to_numpy(object)),
        roles=cut(instances["_role"].to_numpy(object)),
        aborted=cut(instances["_aborted"].to_numpy(bool)),
        starts=_times(instances[START_TIMESTAMP]),
        ends=_times(until),
        offsets=offsets,
        payloads=None if fields is None else cut(fields),
        robots=instances[ROBOT].to_numpy(object)[offsets[:-1]].tolist(),
    )


def _received_payloads(instances: pd.DataFrame) -> np.ndarray | None:
    """Each instance's payload fields where it received a message with one (each distinct
    payload text read once); ``None`` when no received message has a payload."""
    if MSG_PAYLOAD not in instances.columns:
        return None
    received = (instances["_role"] == RECEIVE).to_numpy(bool) & instances[
        MSG_PAYLOAD
    ].notna().to_numpy(bool)
    if not received.any():
        return None
    codes, texts = pd.factorize(instances[MSG_PAYLOAD].to_numpy(object)[received])
    parsed = np.empty(len(texts), dtype=object)
    parsed[:] = [payload_fields(text) for text in texts]
    fields = np.empty(len(instances), dtype=object)
    fields[:] = [()] * len(instances)
    fields[received] = parsed[codes]
    return fields


def _times(times: pd.Series) -> np.ndarray:
    """Times compared only where a trigger is: numpy datetimes (NaT unequal to itself, as a
    Timestamp is) rather than a Timestamp object per instance."""
    if pd.api.types.is_datetime64_any_dtype(times):
        return times.to_numpy("datetime64[ns]")
    return times.to_numpy(object)  # times of several offsets, kept as objects


def _behaving_triggers(traces: Traces) -> set[str]:
    """The triggers of a log that records no interruption (see :func:`triggers`), counted
    over integer codes of all traces at once."""
    if not traces.labels:
        return set()
    codes, names = pd.factorize(
        np.fromiter(itertools.chain.from_iterable(traces.labels), dtype=object)
    )
    kinds = len(names)
    lengths = np.diff(traces.offsets)
    trace = np.repeat(np.arange(len(lengths)), lengths)
    position = np.arange(len(codes)) - np.asarray(traces.offsets)[trace]
    sent = np.fromiter(
        (role == SEND for role in itertools.chain.from_iterable(traces.roles)), dtype=bool
    )
    # a candidate comes at most once in each trace, never first, and is not sent
    _, inverse, times = np.unique(trace * kinds + codes, return_inverse=True, return_counts=True)
    ruled_out = (times[inverse] != 1) | (position == 0) | sent
    candidate = np.bincount(codes[ruled_out], minlength=kinds) == 0
    # it cuts in: some activity just before it is followed by it in less than half of its
    # occurrences
    occurs = np.bincount(codes, minlength=kinds)
    within = trace[1:] == trace[:-1]
    follows = np.bincount(
        codes[:-1][within] * kinds + codes[1:][within], minlength=kinds * kinds
    ).reshape(kinds, kinds)
    cuts_in = ((follows > 0) & (follows * 2 < occurs[:, None])).any(axis=0)
    # two candidates seen in both orders are steps done side by side (a parallel block of
    # once-per-run steps cuts into whatever came before it just as often), not interruptions
    swapped = (follows > 0) & (follows.T > 0) & candidate[:, None] & candidate[None, :]
    return {str(names[code]) for code in np.flatnonzero(candidate & cuts_in & ~swapped.any(0))}


@dataclass(slots=True)
class _Split:
    """A type's traces cut into the process part and the handlers' parts."""

    main: list[list[str]] = field(default_factory=list)
    handled: dict[str, list[list[str]]] = field(default_factory=lambda: defaultdict(list))
    tags: dict[str, list[tuple[str, ...]]] = field(default_factory=lambda: defaultdict(list))
    went_on: dict[str, bool] = field(default_factory=lambda: defaultdict(bool))
    abandoned: dict[str, Counter] = field(default_factory=lambda: defaultdict(Counter))
    caught: dict[str, list[Caught]] = field(default_factory=lambda: defaultdict(list))


@dataclass(slots=True)
class Heard:
    """Signals a robot type heard while busy (:func:`heard_while_busy`): their labels, and
    for every instance of the type's traces (flat, in trace order) the end, in ticks, of the
    latest-ending activity that was running when it started."""

    labels: set[str]
    busy_until: np.ndarray


def heard_while_busy(traces: Traces) -> Heard:
    """The received signals a robot always heard while it was busy with something else.

    A receipt is heard while busy when an activity of the same robot (no message, ended
    normally, not cut short) started before it and ended after it began: the robot took the
    signal without stopping, so something listened all along, as an event sub-process that
    does not interrupt (FAME's non-interrupting handler, G2.2). A signal is such a trigger
    when every receipt of it in the type's traces was heard so; a receipt that sometimes
    came while the robot waited for it is a catch in its process. Worked out over all
    traces at once: the running maximum of the activities' ends, read just before the
    first instance that starts at the receipt's moment."""
    if not traces.labels:
        return Heard(set(), np.array([], dtype=np.int64))
    roles = np.fromiter(itertools.chain.from_iterable(traces.roles), dtype=object)
    received = roles == RECEIVE
    if not received.any():
        return Heard(set(), np.array([], dtype=np.int64))
    starts, ends = _as_ticks(traces.starts), _as_ticks(traces.ends)
    aborted = np.fromiter(itertools.chain.from_iterable(traces.aborted), dtype=bool)
    working = pd.isna(roles) & ~aborted & (ends != _NEVER)
    lengths = np.diff(traces.offsets)
    trace = np.repeat(np.arange(len(lengths)), lengths)
    latest = pd.Series(np.where(working, ends, _NEVER)).groupby(trace).cummax().to_numpy()
    # the first instance of each (trace, moment): what started before it, started earlier
    first = np.ones(len(starts), dtype=bool)
    first[1:] = (trace[1:] != trace[:-1]) | (starts[1:] != starts[:-1])
    tie = np.maximum.accumulate(np.where(first, np.arange(len(starts)), 0))
    before = tie - 1
    own = (before >= 0) & (trace[np.maximum(before, 0)] == trace)
    busy_until = np.where(own, latest[np.maximum(before, 0)], _NEVER)
    heard = received & (busy_until > starts)
    labels = np.fromiter(itertools.chain.from_iterable(traces.labels), dtype=object)
    codes, names = pd.factorize(labels[received])
    always = np.bincount(codes[~heard[received]], minlength=len(names)) == 0
    return Heard({str(name) for name in names[always]}, busy_until)


#: the tick of an instance that never ended
_NEVER = np.iinfo(np.int64).min


def _as_ticks(times: np.ndarray) -> np.ndarray:
    """Times as integer nanoseconds (:data:`_NEVER` where missing)."""
    if times.dtype.kind != "M":  # times of several offsets, kept as objects
        times = pd.to_datetime(pd.Series(times), utc=True).dt.tz_localize(None).to_numpy()
    return times.astype("datetime64[ns]").astype(np.int64)


def handled_parts(instances: pd.DataFrame, *, records_aborts: bool) -> _Split:
    """A type's traces cut at its triggers (:func:`triggers`) and at the signals it heard
    while busy (:func:`heard_while_busy`)."""
    traces = per_trace(instances)
    found = triggers(instances, traces, records_aborts=records_aborts)
    return split_traces(traces, found, heard_while_busy(traces))


def split_traces(traces: Traces, found: set[str], heard: Heard | None = None) -> _Split:
    """Each trace's instances outside the handlers (the process), and each handler's own.

    A handler runs from its trigger to the end of the trace, or to the first activity that
    begins a trace of its type (the robot took up its process again); the handler of a
    signal heard while busy (``heard``) holds what the robot began while the activity the
    signal came in was still running, and the robot went on after it. The event
    sub-process' own instance, where the engine tags one, is recorded apart
    (:func:`_own_instance`)."""
    result = _Split()
    listened = heard.labels - found if heard is not None else set()
    cutting = found | listened
    firsts = {trace[0] for trace in traces.labels}
    for number, (labels, aborted) in enumerate(zip(traces.labels, traces.aborted, strict=True)):
        if not cutting.intersection(labels):  # most traces: nothing to cut
            result.main.append(labels)
            _catches(result, traces, number, range(len(labels)))
            continue
        starts, ends = traces.times(number)
        main: list[str] = []
        kept: list[int] = []
        position = 0
        while position < len(labels):
            label = labels[position]
            if label in listened and heard is not None:
                end = _busy_end(traces, heard, number, position)
                result.tags[label].append(_own_instance(labels, starts, ends, position, end))
                result.handled[label].append(labels[position + 1 : end])
                result.went_on[label] = True
                position = end
                continue
            if label not in found:
                main.append(label)
                kept.append(position)
                position += 1
                continue
            for before in range(position - 1, -1, -1):
                if aborted[before]:
                    result.abandoned[label][labels[before]] += 1
                    break
            end = position + 1
            while end < len(labels) and labels[end] not in firsts:
                end += 1
            result.tags[label].append(_own_instance(labels, starts, ends, position, end))
            result.handled[label].append(labels[position + 1 : end])
            result.went_on[label] |= end < len(labels)
            position = end
        result.main.append(main)
        _catches(result, traces, number, kept)
    return result


def _catches(result: _Split, traces: Traces, number: int, kept: Sequence[int]) -> None:
    """The catches with a payload among trace ``number``'s instances ``kept`` in the
    process, each with the activities of the process after it (:func:`windows`)."""
    if traces.payloads is None:
        return
    fields = traces.payloads[number]
    if not any(fields[position] for position in kept):
        return
    labels, roles = traces.labels[number], traces.roles[number]
    caught = {labels[position] for position in kept if roles[position] == RECEIVE}
    robot = traces.robots[number]
    main = [labels[position] for position in kept]
    for label, found in windows(main, [fields[p] for p in kept], caught).items():
        for at, after in found:
            result.caught[label].append(Caught(fields[kept[at]], robot, after))


def _busy_end(traces: Traces, heard: Heard, number: int, trigger: int) -> int:
    """Where the handler of a signal heard while busy ends in trace ``number``: at the
    first instance that began once the activity the signal came in had ended."""
    begin = traces.offsets[number]
    until = heard.busy_until[begin + trigger]
    starts = _as_ticks(traces.times(number)[0])
    end = trigger + 1
    while end < len(starts) and starts[end] < until:
        end += 1
    return end


def _own_instance(
    labels: list[str], starts: np.ndarray, ends: np.ndarray, trigger: int, end: int
) -> tuple[str, ...]:
    """The event sub-process' own instance in a handler's part ``trigger + 1 .. end`` of a
    trace, as a 1-tuple (empty when there is none): the engine tags the sub-process right
    after its trigger, at the same moment, and it lasts as long as the work inside it."""
    first = trigger + 1
    if first >= end or starts[first] != starts[trigger]:
        return ()
    rest = ends[first + 1 : end]
    if len(rest) == 0 or not all(_no_later(until, ends[first]) for until in rest):
        return ()
    return (labels[first],)


def _no_later(until: Any, bound: Any) -> bool:
    """Whether an instance ending at ``until`` ended no later than ``bound`` (NaT: never
    ended, so later than any time)."""
    if pd.isna(bound):
        return True
    return not pd.isna(until) and until <= bound


# -- mining ------------------------------------------------------------------------------------


def mine(
    traces: list[list[str]], noise: float = 0.0, roles: Mapping[str, str | None] | None = None
) -> Block:
    """The inductive miner's process tree of ``traces`` as blocks (an empty trace is a run
    that does nothing, which the tree allows by a skip). With the activities' message
    ``roles``, a throw and the wait that always follows it are mined as one step
    (:mod:`robotale.discovery.answers`), so the robot waits for each answer."""
    pairs = answered(traces, roles) if roles else {}
    if pairs:
        traces = as_units(traces, pairs)
    if not noise:
        # without a noise threshold the miner's cuts depend on which steps follow which, not
        # on how often: each variant once gives the same tree, faster
        traces = [list(variant) for variant in dict.fromkeys(tuple(t) for t in traces)]
    if not any(traces):
        return Tau()
    # pm4py: 2 s to import and a banner: discovery only
    from robotale.discovery.inductive import inductive_tree

    block = expanded(from_process_tree(inductive_tree(traces, noise)))
    if any(not trace for trace in traces):
        from robotale.discovery.layout import Operator  # the one place a run may be empty

        block = Operator("xor", [block, Tau()])
    return block


#: the columns discovery reads: the rest of a log (positions, batteries ...) is not carried
#: through the pairing and the split into pools
_READ = {*REQUIRED, ROBOT, ROBOT_TYPE, LIFECYCLE, STATE, MSG_ROLE, MSG_PAYLOAD, *INSTANCE_KEYS}


def discover_collaboration(
    log: pd.DataFrame, selection: LogFilter | None = None, *, noise: float = 0.0
) -> Collaboration:
    """The BPMN collaboration the robots of ``log`` followed (see the module's text)."""
    if ROBOT in log.columns and ROBOT_TYPE not in log.columns:  # so --robot-type can filter
        log = log.assign(
            **{ROBOT_TYPE: log[ROBOT].astype("string").map(robot_type, na_action="ignore")}
        )
    events = filter_log(log, selection)
    instances = typed_instances(events[[c for c in events.columns if c in _READ]], by_type=True)
    pools, first = [], {}
    records_aborts = bool(instances["_aborted"].any())
    for name, mine_ in _by_type(instances):
        pools.append(_pool(name, mine_, noise, records_aborts))
        first[str(name)] = mine_[START_TIMESTAMP].min()  # the group at hand: no text compare
    pools.sort(key=lambda pool: first[pool.name])
    info = {
        "filter": selection.describe() if selection else {},
        "events": len(events),
        "cases": int(events[CASE].nunique()),
        "miner": "pm4py inductive miner" + (f" (noise {noise:g})" if noise else ""),
    }
    return Collaboration(pools, _signals(instances), info)


def _by_type(instances: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    """Each robot type and its instances, from instances laid out ``by_type``
    (:func:`typed_instances`): a slice of rows each, not a copy per group."""
    types = instances[ROBOT_TYPE].to_numpy(object)
    bounds = [0, *(np.flatnonzero(types[1:] != types[:-1]) + 1).tolist(), len(types)]
    return [
        (str(types[begin]), instances.iloc[begin:end])
        for begin, end in itertools.pairwise(bounds)
        if end > begin
    ]


def _pool(name: str, instances: pd.DataFrame, noise: float, records_aborts: bool) -> Pool:
    parts = handled_parts(instances, records_aborts=records_aborts)
    stats = _stats(instances)
    roles = {label: activity.role for label, activity in stats.items()}
    handlers = [
        _handler(label, instances, parts, noise, roles)
        for label in sorted(parts.handled)
        if parts.handled[label]
    ]
    return Pool(
        name=name,
        robots=sorted(instances[ROBOT].unique()),
        block=mine(parts.main, noise, roles),
        handlers=handlers,
        stats=stats,
        traces=len(parts.main),
        caught=dict(parts.caught),
    )


def _handler(
    label: str,
    instances: pd.DataFrame,
    parts: _Split,
    noise: float,
    roles: Mapping[str, str | None],
) -> Handler:
    tag = _tag(parts.tags[label])
    traces = parts.handled[label]
    if tag is not None:  # the sub-process itself, not a step inside it
        traces = [rest[1:] for rest in traces]
    received = label.endswith(CAUGHT) and _role(instances, label) == RECEIVE
    return Handler(
        trigger=label,
        kind="signal" if received else "error",
        interrupting=not parts.went_on[label],
        block=mine(traces, noise, roles),
        count=len(traces),
        abandoned=dict(parts.abandoned[label]),
        tag=tag,
    )


def _tag(moved: list[tuple[str, ...]]) -> str | None:
    """The sub-process' own tag: the one instance every occurrence has as its own (the
    engine tags an event sub-process right after its start event catches)."""
    kinds = set(moved)
    if len(kinds) == 1 and len(next(iter(kinds))) == 1:
        return next(iter(kinds))[0]
    return None


def _role(instances: pd.DataFrame, label: str) -> str | None:
    roles = instances.loc[instances[ACTIVITY].astype(str) == label, "_role"].dropna()
    return str(roles.iloc[0]) if len(roles) else None


def _stats(instances: pd.DataFrame) -> dict[str, ActivityStats]:
    """Each activity's statistics, its instances found by integer codes (a slice of arrays
    per activity, not a DataFrame group): numpy's mean and median are what pandas' give."""
    codes, labels = pd.factorize(instances[ACTIVITY], sort=True)
    robots = instances[ROBOT].to_numpy(object)
    durations = instances[DURATION].to_numpy(float)
    finished = instances[FINISHED].to_numpy(bool)
    roles = instances["_role"].to_numpy(object)
    has_role = instances["_role"].notna().to_numpy(bool)
    stats = {}
    for code, at in _positions(codes, len(labels)):
        done = durations[at][finished[at]]
        done = done[~np.isnan(done)]
        known = at[has_role[at]]
        stats[str(labels[code])] = ActivityStats(
            count=len(at),
            robots=sorted(set(robots[at])),
            mean=float(np.mean(done)) if len(done) else None,
            median=float(np.median(done)) if len(done) else None,
            role=str(roles[known[0]]) if len(known) else None,
        )
    return stats


def _positions(codes: np.ndarray, kinds: int) -> list[tuple[int, np.ndarray]]:
    """For each code that occurs (-1, missing, left out), its positions in order."""
    order = np.argsort(codes, kind="stable")
    bounds = np.searchsorted(codes[order], np.arange(kinds + 1))
    return [
        (code, order[bounds[code] : bounds[code + 1]])
        for code in range(kinds)
        if bounds[code + 1] > bounds[code]
    ]


def signal_of(label: str) -> str:
    """The signal a message activity is about: ``weed_position!`` -> ``weed_position``."""
    return label.rstrip(THROWN + CAUGHT)


def _signals(instances: pd.DataFrame) -> dict[str, Signal]:
    roles = instances["_role"].to_numpy(object)
    sent, got = roles == SEND, roles == RECEIVE
    messages = np.flatnonzero(sent | got)
    codes, labels = pd.factorize(
        instances[ACTIVITY].to_numpy(object)[messages], use_na_sentinel=False
    )
    named, names = pd.factorize(
        np.array([signal_of(str(label)) for label in labels], dtype=object), sort=True
    )
    signal = named[codes] if len(codes) else codes
    kinds = instances[ROBOT_TYPE].to_numpy(object)[messages]
    sent, got = sent[messages], got[messages]
    signals = {}
    for code, at in _positions(signal, len(names)):
        name = str(names[code])
        signals[name] = Signal(
            name=name,
            sent=int(sent[at].sum()),
            received=int(got[at].sum()),
            senders=sorted(set(kinds[at][sent[at]])),
            receivers=sorted(set(kinds[at][got[at]])),
        )
    return signals
