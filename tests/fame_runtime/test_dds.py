"""robotale on real Cyclone DDS, pinned to the loopback interface, on a domain of its own:
two engine processes run the agri mission into one bag, plain DDS code that knows only the
ROS 2 names talks to robotale, and DDS itself keeps QoS-incompatible pairs apart."""

import contextlib
import gc
import itertools
import os
import time
from collections import Counter
from dataclasses import dataclass, replace
from pathlib import Path

import pytest

cyclonedds = pytest.importorskip("cyclonedds")

from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.idl import IdlStruct  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from dds_domain import loopback  # noqa: E402
from fame_suite import MODELS  # noqa: E402
from patience import patience  # noqa: E402

from robotale.cli import main  # noqa: E402
from robotale.fame_runtime.clock import WallClock  # noqa: E402
from robotale.fame_runtime.dds import DdsBus, dds_qos  # noqa: E402
from robotale.fame_runtime.engine import Engine  # noqa: E402
from robotale.fame_runtime.parser import parse  # noqa: E402
from robotale.fame_runtime.qos import DEFAULT_QOS, incompatibilities  # noqa: E402
from robotale.fame_runtime.rostypes import idl_type, to_sample  # noqa: E402

pytestmark = pytest.mark.timeout(180)

AGRI = Path(__file__).resolve().parents[2] / "robotale" / "sim" / "scenarios" / "agri.bpmn"
POINT = "geometry_msgs/msg/Point"
RANGE, ODOMETRY = "sensor_msgs/msg/Range", "nav_msgs/msg/Odometry"


@pytest.fixture(autouse=True)
def loopback_domain(tmp_path_factory, monkeypatch) -> int:
    return loopback(tmp_path_factory, monkeypatch)


def instances_made(monkeypatch, kind: type) -> list:
    """Every instance of ``kind`` made from now on in this test, in the order made."""
    made: list = []
    original = kind.__init__

    def recording(self, *args, **kwargs):
        original(self, *args, **kwargs)
        made.append(self)

    monkeypatch.setattr(kind, "__init__", recording)
    return made


@pytest.fixture(autouse=True)
def left_participants(monkeypatch):
    """Every participant a test makes (its own, its buses') leaves the domain after it. One
    left to the garbage collector stays on the domain until a full collection, which in a
    long test session comes late, or never while a failed test's traceback holds it: a later
    test's readers then match its writers and get their transient-local samples."""
    from robotale.fame_runtime.dds import leave

    made = instances_made(monkeypatch, DomainParticipant)
    yield made
    for participant in made:
        leave(participant)


@pytest.fixture(autouse=True)
def closed_buses(monkeypatch, left_participants):
    """Every bus a test opens is closed after it: a bus left to the garbage collector keeps
    Cyclone calling into Python until it is finalised, which can crash a later test."""
    opened = instances_made(monkeypatch, DdsBus)
    yield opened
    for bus in opened:
        bus.close()
    gc.collect()


@dataclass
class String_(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    """std_msgs/msg/String as a ROS 2 node declares it, written here by hand."""

    data: str


def wait_until(condition, clock: WallClock, seconds: float = 10.0) -> None:
    clock.run(until=clock.now() + seconds, stop_when=condition)


def matched(endpoint, seconds: float = 10.0) -> None:
    """Wait for DDS discovery to match ``endpoint`` with a peer."""
    status = getattr(endpoint, "get_publication_matched_status", None) or (
        endpoint.get_subscription_matched_status
    )
    deadline = time.monotonic() + seconds
    while status().current_count == 0 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert status().current_count > 0, "discovery did not match the endpoint"


def test_two_engine_processes_run_agri_into_one_bag_whose_comm_edges_match(tmp_path, capsys):
    from robotale.ekg.tables import graph_tables
    from robotale.eventlog.preparing import prepare_recordings

    bag = tmp_path / "run"
    skills = str(MODELS / "agri_skills.py")
    robots = "drone,tractor_1"
    args = ["fame", "run", str(AGRI), "--robots", robots, "--skills", skills]
    assert main([*args, "--bus", "dds", "--record", str(bag), "--until", "60"]) == 0
    live = capsys.readouterr()
    assert "# drone: done" in live.err and "# tractor_1: done" in live.err
    # the same mission in one process: the robots do the same things in the same order
    assert main(args) == 0
    simulated = capsys.readouterr().out
    for robot in robots.split(","):
        assert activities(live.out, robot) == activities(simulated, robot)

    # what the nodes printed, message by message: the send's robot and the receive's
    sent = {r[4]: r[1] for r in rows(live.out) if r[5:6] == ["send"]}
    received = [(r[4], r[1]) for r in rows(live.out) if r[5:6] == ["receive"]]
    assert len(received) >= 4  # weed_position, tractor_position, closest_tractor, field_cleaned
    # weed_found comes from the Explore skill, not from a throw: it has no send tag
    assert {m for m, _ in received if m not in sent} == {
        r[4] for r in rows(live.out) if r[2] == "weed_found?"
    }
    expected = sorted({(sent[m], receiver, m) for m, receiver in received if m in sent})

    log = prepare_recordings(bag)
    assert set(log["robot"]) == {"drone", "tractor_1"}
    tables = graph_tables(log, ["robot"])
    robot_of = tables.events["robot"]
    comm = sorted(
        {(robot_of[s], robot_of[t], m) for s, t, m in tables.comm.itertuples(index=False)}
    )
    assert comm == expected


def alerts_heard(reader, count: int, settle: float, meanwhile=None) -> list[dict]:
    """The alerts a /robotale/alerts reader gets: until ``count`` came (or a long wait), then
    those ``settle`` seconds more bring. ``meanwhile(heard)`` is called at each look."""
    heard: list = []
    deadline = time.monotonic() + patience(30)
    while len(heard) < count and time.monotonic() < deadline:
        heard += alerts_taken(reader)
        if meanwhile is not None:
            meanwhile(heard)
        time.sleep(0.05)
    time.sleep(settle)
    return heard + alerts_taken(reader)


def alerts_taken(reader) -> list[dict]:
    """The alerts a /robotale/alerts reader holds now (not the notice that a monitor left)."""
    import json

    return [json.loads(s.data) for s in reader.take(N=10) if s.sample_info.valid_data]


@contextlib.contextmanager
def monitored(driver, name: str, args: list[str]):
    """A ``robotale monitor`` process storing the live run ``name`` (``args``: the model and
    options) and a plain cyclonedds reader of /robotale/alerts; the live run forgotten after."""
    import subprocess
    import sys

    from cyclonedds.core import Policy, Qos

    from robotale.ekg.live import delete_live
    from robotale.ekg.logs import delete_log

    participant = DomainParticipant(int(os.environ["ROS_DOMAIN_ID"]))
    kept = Qos(
        Policy.Reliability.Reliable(10**9), Policy.Durability.TransientLocal, Policy.History.KeepAll
    )
    reader = DataReader(participant, Topic(participant, "rt/robotale/alerts", String_), qos=kept)
    command = [sys.executable, "-m", "robotale", "monitor", *args, "--log", name]
    monitor = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert monitor.stderr.readline().startswith("# monitoring "), monitor.stderr.read()
        yield monitor, reader
    finally:
        if monitor.poll() is None:
            monitor.kill()
        with contextlib.suppress(ValueError):  # what it said, unless a test read it already
            print("the monitor said:", *monitor.communicate(), sep="\n")  # shown on failure
        delete_live(driver, name)
        delete_log(driver, name)  # the live run's event knowledge graph


def interrupted(monitor) -> tuple[str, str]:
    """What a ``robotale monitor`` process printed (out, err) until Ctrl-C ended it well."""
    import signal

    monitor.send_signal(signal.SIGINT)
    said, complaints = monitor.communicate(timeout=patience(60))
    assert monitor.returncode == 0, complaints
    return said, complaints


def rows(text: str) -> list[list[str]]:
    return [line.split("\t") for line in text.splitlines() if "\t" in line]


def activities(text: str, robot: str) -> list[tuple[str, str]]:
    return sorted((r[2], r[3]) for r in rows(text) if r[1] == robot)


def test_a_plain_ros2_style_reader_receives_a_robotale_signal():
    participant = DomainParticipant(int(os.environ["ROS_DOMAIN_ID"]))
    reader = DataReader(participant, Topic(participant, "rt/chatter", String_))
    clock = WallClock()
    bus = DdsBus(clock, node="talker")
    writer = bus.writer("/chatter", "std_msgs/msg/String", sender="talker")
    matched(writer)
    bus.publish("/chatter", {"data": "hello"}, msgtype="std_msgs/msg/String", sender="talker")
    samples = list(reader.take_iter(timeout=5_000_000_000))[:1]
    assert [s.data for s in samples] == ["hello"]


def test_a_plain_writers_sample_is_caught_by_a_robotale_signal_catch_event(tmp_path):
    model = tmp_path / "listener.bpmn"
    model.write_text(LISTENER)
    clock = WallClock()
    bus = DdsBus(clock, node="listener")
    tags = []
    engine = Engine(
        parse(model).processes["listener"],
        robot="listener",
        bus=bus,
        clock=clock,
        tag_sink=tags.append,
    )
    engine.start()
    participant = DomainParticipant(int(os.environ["ROS_DOMAIN_ID"]))
    writer = DataWriter(participant, Topic(participant, "rt/chatter", String_))
    matched(writer)
    writer.write(String_(data="from outside"))
    wait_until(lambda: engine.completed == 1, clock)
    caught = [t for t in tags if t.activity == "chatter?" and t.lifecycle == "complete"]
    assert len(caught) == 1 and caught[0].payload == '{"data":"from outside"}'
    assert engine.variables["heard"] == "from outside"


LISTENER = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"
    xmlns:camunda="http://camunda.org/schema/1.0/bpmn" id="listener">
  <bpmn:process id="listener">
    <bpmn:startEvent id="start" name="chatter">
      <bpmn:extensionElements><camunda:properties>
        <camunda:property name="type" value="std_msgs/msg/String" />
      </camunda:properties></bpmn:extensionElements>
      <bpmn:signalEventDefinition />
    </bpmn:startEvent>
    <bpmn:scriptTask id="note" name="Note"><bpmn:script>heard = chatter["data"]</bpmn:script>
    </bpmn:scriptTask>
    <bpmn:endEvent id="end" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="note" />
    <bpmn:sequenceFlow id="f2" sourceRef="note" targetRef="end" />
  </bpmn:process>
</bpmn:definitions>
"""


def test_a_qos_incompatible_pair_never_talks_over_dds():
    clock = WallClock()
    warnings: list[str] = []
    talker = DdsBus(clock, node="talker")
    listener = DdsBus(clock, node="listener", on_warning=warnings.append)
    got: list = []
    listener.subscribe("/p", got.append, msgtype=POINT, owner="listener")  # reliable
    lossy = replace(DEFAULT_QOS, reliability="best_effort")
    control = listener.reader("/q", POINT)  # a compatible pair, to know discovery is done
    listener.subscribe("/q", got.append, msgtype=POINT)
    matched(talker.writer("/q", POINT, sender="talker"))
    talker.writer("/p", POINT, lossy, sender="talker")
    wait_until(lambda: bool(warnings), clock, 5.0)
    talker.publish("/p", {"x": 1.0}, msgtype=POINT, sender="talker", qos=lossy)
    talker.publish("/q", {"x": 2.0}, msgtype=POINT, sender="talker")
    wait_until(lambda: len(got) >= 2, clock, 2.0)
    assert [e.topic for e in got] == ["/q"]  # the best-effort /p never arrived
    assert control.reader.get_subscription_matched_status().current_count == 1
    assert warnings and warnings[0].startswith("/p:") and "reliability" in warnings[0]


def test_a_transient_local_late_joiner_gets_the_stored_samples_over_dds():
    clock = WallClock()
    latched = replace(DEFAULT_QOS, durability="transient_local", depth=2)
    talker = DdsBus(clock, node="talker")
    for x in (1.0, 2.0, 3.0):
        talker.publish("/latched", {"x": x}, msgtype=POINT, sender="talker", qos=latched)
    late = DdsBus(clock, node="late")
    got, volatile = [], []
    late.subscribe("/latched", got.append, msgtype=POINT, qos=latched)
    wait_until(lambda: len(got) >= 2, clock, 5.0)
    late.subscribe("/latched", volatile.append, msgtype=POINT)
    wait_until(lambda: False, clock, 0.5)
    assert [e.data["x"] for e in got] == [2.0, 3.0]  # the writer keeps depth 2
    assert {e.sender for e in got} == {"talker"}
    assert volatile == []  # a volatile reader asks for no history


#: every value a model can give the policies that decide a match (None: infinite)
MATCHING = {
    "reliability": ("reliable", "best_effort"),
    "durability": ("volatile", "transient_local"),
    "liveliness": ("automatic", "manual_by_topic"),
    "deadline": (None, 1.0, 2.0),
    "lease_duration": (None, 1.0, 2.0),
}
#: policies that never prevent a match, spread over the pairs
OTHERS = (
    {},
    {"history": "keep_all", "lifespan": 1.0},
    {"history": "keep_last", "depth": 1, "lifespan": 5.0},
)


@pytest.mark.slow
def test_fame_checks_verdict_is_cyclone_ddss_matching_on_every_policy_combination():
    """Each of the 72 x 72 offered/requested profiles as a real Cyclone writer and reader
    (local endpoints of one participant match at once): they match exactly when the C-QoS
    rules find no incompatibility, and Cyclone reports the others as incompatible."""
    profiles = [
        replace(DEFAULT_QOS, **dict(zip(MATCHING, values, strict=True)))
        for values in itertools.product(*MATCHING.values())
    ]
    participant = DomainParticipant(int(os.environ["ROS_DOMAIN_ID"]))
    string = idl_type("std_msgs/msg/String")
    disagreements, blocked = [], 0
    for n, (offered, requested) in enumerate(itertools.product(profiles, profiles)):
        offered = replace(offered, **OTHERS[n % 3])
        requested = replace(requested, **OTHERS[n // 3 % 3])
        topic = Topic(participant, f"rt/pair_{n}", string)
        writer = DataWriter(participant, topic, qos=dds_qos(offered))
        reader = DataReader(participant, topic, qos=dds_qos(requested))
        talks = writer.get_publication_matched_status().current_count == 1
        refused = reader.get_requested_incompatible_qos_status().total_count > 0
        compatible = not incompatibilities(offered, requested)
        blocked += not compatible
        if (talks, refused) != (compatible, not compatible):
            disagreements.append((offered, requested, talks, refused))
    assert disagreements == []
    # by hand: 3 of the 4 pairs of each two-valued policy match, 6 of the 9 of each period
    assert blocked == 72 * 72 - 3**3 * 6**2


PATROL = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="patrol_forever">
  <bpmn:collaboration id="c">
    <bpmn:participant id="p_rover" name="Rover" processRef="Rover" />
    <bpmn:participant id="p_drone" name="Drone" processRef="Drone" />
  </bpmn:collaboration>
  {processes}
</bpmn:definitions>
"""
PATROLLER = """<bpmn:process id="{pool}">
    <bpmn:startEvent id="{pool}_start" />
    <bpmn:task id="{pool}_patrol" name="Patrol" />
    <bpmn:intermediateCatchEvent id="{pool}_pause" name="pause">
      <bpmn:timerEventDefinition><bpmn:timeDuration>PT0.2S</bpmn:timeDuration>
      </bpmn:timerEventDefinition>
    </bpmn:intermediateCatchEvent>
    <bpmn:sequenceFlow id="{pool}_f1" sourceRef="{pool}_start" targetRef="{pool}_patrol" />
    <bpmn:sequenceFlow id="{pool}_f2" sourceRef="{pool}_patrol" targetRef="{pool}_pause" />
    <bpmn:sequenceFlow id="{pool}_f3" sourceRef="{pool}_pause" targetRef="{pool}_patrol" />
    <bpmn:subProcess id="{pool}_safe" name="Safe State" triggeredByEvent="true">
      <bpmn:startEvent id="{pool}_s_start" name="emergency">
        <bpmn:errorEventDefinition /></bpmn:startEvent>
      <bpmn:task id="{pool}_stop_motors" name="Stop Motors" />
      <bpmn:endEvent id="{pool}_s_end" />
      <bpmn:sequenceFlow id="{pool}_s1" sourceRef="{pool}_s_start" targetRef="{pool}_stop_motors" />
      <bpmn:sequenceFlow id="{pool}_s2" sourceRef="{pool}_stop_motors" targetRef="{pool}_s_end" />
    </bpmn:subProcess>
  </bpmn:process>"""


@pytest.mark.slow
def test_ctrl_c_stops_every_robot_through_its_safe_state_and_closes_the_bag(tmp_path):
    """As a terminal's Ctrl-C does: SIGINT to the whole process group of a DDS run."""
    import signal
    import subprocess
    import sys

    from robotale.eventlog.preparing import prepare_recordings

    model = tmp_path / "patrol.bpmn"
    processes = "\n  ".join(PATROLLER.format(pool=pool) for pool in ("Rover", "Drone"))
    model.write_text(PATROL.format(processes=processes))
    bag = tmp_path / "run"
    command = [sys.executable, "-m", "robotale", "fame", "run", str(model)]
    command += ["--robots", "rover,drone", "--bus", "dds", "--record", str(bag), "--until", "600"]
    environment = {**os.environ, "PYTHONUNBUFFERED": "1"}  # tags reach us as they happen
    run = subprocess.Popen(
        command,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        env=environment,
    )
    try:
        seen: list[str] = []
        for line in run.stdout:  # wait until both robots patrol (so the recorder listens)
            seen.append(line)
            if all(patrols(seen, robot) >= 3 for robot in ("rover", "drone")):
                break
        os.killpg(run.pid, signal.SIGINT)
        rest, errors = run.communicate(timeout=patience(90))
    finally:
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGKILL)
    printed = rows("".join(seen) + rest)
    assert run.returncode == 130, errors
    for robot in ("rover", "drone"):
        assert [robot, "stop_motors", "complete"] in [r[1:4] for r in printed], errors
        assert f"# {robot}: stopped (interrupted)" in errors
    assert "# recorded " in errors
    # the bag was closed whole: it prepares, and holds every tag the robots printed
    log = prepare_recordings(bag)
    recorded = Counter(
        log[["robot", "concept:name", "lifecycle:transition"]].itertuples(index=False, name=None)
    )
    assert recorded == Counter(tuple(r[1:4]) for r in printed)


def patrols(lines: list[str], robot: str) -> int:
    return sum(f"\t{robot}\tpatrol\tcomplete" in line for line in lines)


@pytest.mark.slow
def test_robotale_record_keeps_what_nodes_started_by_hand_say_at_once(tmp_path):
    """``robotale record`` first, then one ``fame node`` per robot (as on two machines): the
    caller throws the moment the listener is up, and the bag still has that message, because
    robots wait until a recorder on the domain reads their topics; Ctrl-C closes the bag.
    A robot's own topics that are not robotale's (a range sensor, odometry at full rate),
    written here with plain cyclonedds, are in the bag message for message."""
    import signal
    import subprocess
    import sys

    from rosbags.highlevel import AnyReader

    from robotale.eventlog.preparing import prepare_recordings

    model = MODELS / "hello_at_once.bpmn"
    bag = tmp_path / "bag"
    robotale = [sys.executable, "-m", "robotale"]
    recorder = subprocess.Popen(
        [*robotale, "record", str(bag), "--robots", "caller,listener"],
        stderr=subprocess.PIPE,
        text=True,
    )
    assert recorder.stderr.readline().startswith("# recording ")  # it listens: start the robots
    sensors = DomainParticipant(int(os.environ["ROS_DOMAIN_ID"]))
    own = {
        "/caller/range": (RANGE, [{"range": 0.1 * k, "max_range": 4.0} for k in range(5)]),
        "/caller/odom": (ODOMETRY, [{"pose": {"pose": {"position": {"x": k}}}} for k in range(40)]),
    }
    for topic, (msgtype, samples) in own.items():
        kept = dds_qos(replace(DEFAULT_QOS, history="keep_all"))  # none overwritten unsent
        writer = DataWriter(sensors, Topic(sensors, "rt" + topic, idl_type(msgtype)), qos=kept)
        matched(writer, 30.0)  # the recorder found the topic and reads it
        for sample in samples:
            writer.write(to_sample(msgtype, sample))
    node = [*robotale, "fame", "node", str(model), "--robots", "caller,listener"]
    nodes = {
        robot: subprocess.Popen(
            [*node, "--robot", robot, "--until", "60"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for robot in ("caller", "listener")
    }
    try:
        said = {robot: run.communicate(timeout=patience(120)) for robot, run in nodes.items()}
        recorder.send_signal(signal.SIGINT)
        recorded = recorder.communicate(timeout=patience(60))[1]
    finally:
        for run in [recorder, *nodes.values()]:
            if run.poll() is None:
                run.kill()
    assert {robot: run.returncode for robot, run in nodes.items()} == {
        "caller": 0,
        "listener": 0,
    }, said
    assert recorder.returncode == 0, recorded
    printed = [row for out, _ in said.values() for row in rows(out)]
    sent = [r for r in printed if r[2] == "hello!" and r[3] == "complete"]
    heard = [r for r in printed if r[2] == "hello?" and r[3] == "complete"]
    assert len(sent) == 1 and [r[4] for r in heard] == [sent[0][4]]
    with AnyReader([bag]) as reader:
        found: dict[str, list] = {}
        for connection, _, raw in reader.messages():
            message = reader.deserialize(raw, connection.msgtype)
            found.setdefault(connection.topic, []).append(message)
    assert [m.data for m in found["/hello"]] == ["hi"]
    assert [m.range for m in found["/caller/range"]] == pytest.approx([0.1 * k for k in range(5)])
    assert [m.pose.pose.position.x for m in found["/caller/odom"]] == list(range(40))
    log = prepare_recordings(bag)
    in_bag = Counter(
        log[["robot", "concept:name", "lifecycle:transition"]].itertuples(index=False, name=None)
    )
    assert in_bag == Counter(tuple(r[1:4]) for r in printed)


@pytest.mark.slow
def test_a_live_run_ingests_with_its_comm_edges(tmp_path, capsys, neo4j_driver, log_name):
    """``fame run --bus dds --record`` then ``robotale ingest`` of the bag, as of a simulated
    run: the stored COMM edge joins the send and the receive the robots printed."""
    from robotale.ekg.connection import database
    from robotale.ekg.logs import log_summary
    from robotale.eventlog.preparing import prepare_recordings
    from robotale.queries import cypher

    bag = tmp_path / "live"
    model = str(MODELS / "hello_at_once.bpmn")
    run = ["fame", "run", model, "--robots", "caller,listener", "--bus", "dds"]
    assert main([*run, "--record", str(bag), "--until", "60"]) == 0
    printed = rows(capsys.readouterr().out)
    sent = {r[4]: r[1:3] for r in printed if r[5:6] == ["send"] and r[3] == "complete"}
    heard = {r[4]: r[1:3] for r in printed if r[5:6] == ["receive"] and r[3] == "complete"}
    expected = sorted((*sent[m], *heard[m], m) for m in heard)
    assert len(expected) == 1

    code = main(["ingest", str(bag), "--log", log_name, "--entities", "robot,msg_id"])
    assert code == 0, capsys.readouterr().err
    records, _, _ = neo4j_driver.execute_query(
        cypher("ekg_comm_edges"), {"log": log_name}, database_=database()
    )
    # an edge from each event of the send (start, complete) to each of the receive
    stored = sorted(
        {(r["fromRobot"], r["sender"], r["toRobot"], r["receiver"], r["msgId"]) for r in records}
    )
    assert stored == expected and len(records) == 4
    assert log_summary(neo4j_driver, log_name)["counts"]["events"] == len(prepare_recordings(bag))


def test_a_dds_run_stopped_at_until_with_a_robot_working_exits_1_saying_where(tmp_path, capsys):
    model = tmp_path / "patrol.bpmn"
    model.write_text(
        PATROL.format(processes=PATROLLER.format(pool="Rover")).replace(
            '<bpmn:participant id="p_drone" name="Drone" processRef="Drone" />', ""
        )
    )
    run = ["fame", "run", str(model), "--robots", "rover", "--bus", "dds", "--until", "5"]
    assert main(run) == 1
    captured = capsys.readouterr()
    assert "# rover: still running at " in captured.err
    place = captured.err.split("# rover is at ", 1)[1].splitlines()[0]
    if rows(captured.out):  # it patrols, or pauses between two patrols
        assert place in ("task Rover_patrol (Patrol)", "intermediateCatchEvent Rover_pause (pause)")
    else:  # a slow machine: its first instance had not run when the time was up
        assert place == "the start of an instance"


def test_a_dds_run_ending_with_an_uncaught_error_exits_1_naming_it(capsys, models):
    run = ["fame", "run", str(models / "errors.bpmn"), "--robots", "tractor_1", "--bus", "dds"]
    run += ["--set", "tractor_1.jammed=false", "--set", 'tractor_1.fail_loudly="overheat"']
    assert main(run) == 1
    err = capsys.readouterr().err
    assert "error 'overheat' thrown at check (Check Blade) was not caught" in err


@pytest.mark.slow
def test_timer_start_events_start_their_robots_over_dds_and_keep_the_mission_going(capsys, models):
    """One process per robot on the wall clock, which starts 20 s before the alarm's date:
    each timer start event starts its process (a duration, a date, a cycle), and no robot calls
    the mission over while the alarm clock's timers are still armed."""
    model = str(models / "timer_starts.bpmn")
    run = ["fame", "run", model, "--bus", "dds", "--start", "2024-05-01T07:59:40Z"]
    run += ["--until", "60"]
    assert main(run) == 0
    captured = capsys.readouterr()
    starts = {}
    for r in rows(captured.out):
        if r[3] == "start":
            starts.setdefault((r[1], r[2]), []).append(float(r[0]))
    assert {("waiter", "serve"), ("alarm_clock", "ring"), ("ticker", "tick")} <= set(starts)
    # each robot's process starts a little after the shared origin and its duration counts
    # from then; the date is 08:00:00 on the shared clock, 20 s after the origin
    assert 3.0 <= starts["waiter", "serve"][0] < 20
    ring = starts["alarm_clock", "ring"][0]
    assert 20.0 <= ring < 21.0
    first, second = starts["ticker", "tick"]
    assert second - first == pytest.approx(2.0, abs=0.3)  # R2/PT2S: twice, 2 s apart
    done = {
        line.split(":")[0][2:]: float(line.split(" at ")[1].split(" s")[0])
        for line in captured.err.splitlines()
        if ": done at " in line
    }
    assert set(done) == {"waiter", "alarm_clock", "ticker"}
    assert min(done.values()) >= ring + 5.0  # nobody left while the snooze was armed


def test_the_models_qos_is_live_a_pair_fame_check_refuses_never_talks_over_dds(capsys, models):
    """qos.bpmn as one process per robot: the drone's best-effort weed_position never reaches
    the tractor's reliable catch (as ``fame check`` says); nobody waits to meet that pair, the
    readers' buses name it, and the run ends at --until with the drone waiting."""
    run = ["fame", "run", str(models / "qos.bpmn"), "--robots", "drone,tractor_1"]
    assert main([*run, "--bus", "dds", "--until", "20"]) == 1
    captured = capsys.readouterr()
    printed = rows(captured.out)
    assert [r[1:4] for r in printed] == [
        ["drone", "weed_position!", "start"],
        ["drone", "weed_position!", "complete"],
    ]
    assert (
        "# warning: /weed_position: a publisher and tractor_1's subscriber cannot talk "
        "(reliability does not match; see robotale fame check)"
    ) in captured.err
    assert "# drone is at intermediateCatchEvent d_position (tractor_position)" in captured.err
    assert "starts with no peer" not in captured.err


@pytest.mark.slow
def test_monitor_stores_the_tags_as_heard_and_alerts_on_silence(tmp_path, capsys, neo4j_driver):
    """``robotale monitor`` watching a ``fame run --bus dds --record``: Neo4j holds each tag
    the robots printed, in each robot's order, and the same events ``prepare`` makes of the
    run's bag; once the robots are done they are silent, and a plain cyclonedds reader of
    /robotale/alerts gets one silence alert per robot, the same ones the monitor stored."""
    import signal
    import subprocess
    import sys
    import uuid

    from cyclonedds.core import Policy, Qos

    from robotale.ekg.live import delete_live, live_alerts, live_tags
    from robotale.ekg.logs import delete_log
    from robotale.eventlog.preparing import prepare_recordings

    name = f"test_monitor_{uuid.uuid4().hex[:8]}"
    model = str(MODELS / "hello_at_once.bpmn")
    alerts = DomainParticipant(int(os.environ["ROS_DOMAIN_ID"]))
    kept = Qos(
        Policy.Reliability.Reliable(10**9), Policy.Durability.TransientLocal, Policy.History.KeepAll
    )
    reader = DataReader(alerts, Topic(alerts, "rt/robotale/alerts", String_), qos=kept)
    watch = [sys.executable, "-m", "robotale", "monitor", model, "--robots", "caller,listener"]
    monitor = subprocess.Popen(
        [*watch, "--log", name, "--silence", "3"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert monitor.stderr.readline().startswith("# monitoring "), monitor.stderr.read()
        bag = tmp_path / "live"
        run = ["fame", "run", model, "--robots", "caller,listener", "--bus", "dds"]
        assert main([*run, "--record", str(bag), "--until", "60"]) == 0
        ended = time.time()  # the monitor's clock: the wall clock
        printed = rows(capsys.readouterr().out)
        heard: list = []
        # both robots ended, so silent: by then the monitor called each silent (and maybe once
        # before, when a robot was slow to start)
        while time.time() < ended + 3 + patience(2):
            heard += alerts_taken(reader)
            time.sleep(0.1)
        monitor.send_signal(signal.SIGINT)
        said, complaints = monitor.communicate(timeout=patience(60))
        assert monitor.returncode == 0, complaints
        stored = live_tags(neo4j_driver, name)
        stored_alerts = live_alerts(neo4j_driver, name)
        heard += alerts_taken(reader)
    finally:
        if monitor.poll() is None:
            monitor.kill()
        delete_live(neo4j_driver, name)
        delete_log(neo4j_driver, name)  # the live run's event knowledge graph
    fields = [(t.robot, t.activity, t.lifecycle, t.msg_id, t.msg_role) for t in stored]
    for robot in ("caller", "listener"):
        assert [f for f in fields if f[0] == robot] == [
            tuple(r[1:6] + [""] * (6 - len(r)))[:5] for r in printed if r[1] == robot
        ]
    log = prepare_recordings(bag)
    prepared = log[["robot", "concept:name", "lifecycle:transition"]]
    assert Counter(prepared.itertuples(index=False, name=None)) == Counter(f[:3] for f in fields)
    assert {a["kind"] for a in heard} == {"silence"}
    for robot in ("caller", "listener"):
        last = max(t.stamp for t in stored if t.robot == robot)
        assert any(a["robot"] == robot and a["stamp"] >= last + 3 for a in heard), heard
    # what was published was stored (one raised as the monitor closed may not reach the reader)
    kept = {(a.stamp, a.kind, a.robot, a.text) for a in stored_alerts}
    assert {(a["stamp"], a["kind"], a["robot"], a["text"]) for a in heard} <= kept
    assert "# alert silence caller" in said


def test_monitor_alerts_a_skipped_activity_within_a_second_of_its_tag(neo4j_driver):
    """A rover that skips Measure (its tags published here over DDS, as a faulty robot's
    engine would): the monitor replays them on the rover's pool and alerts the start of
    Carry On as a deviation, soon after the tag's stamp; Prepare, which the model allows,
    raises nothing. Its battery falling to 15 % raises a battery alert (30 % does not). A
    plain cyclonedds reader of /robotale/alerts gets the alerts."""
    import subprocess
    import sys
    import uuid

    from cyclonedds.core import Policy, Qos

    from robotale.ekg.live import delete_live, live_alerts
    from robotale.ekg.logs import delete_log
    from robotale.fame_runtime.node import KEEP_ALL
    from robotale.fame_runtime.tags import TAG_TYPE, Tag, tag_topic

    name = f"test_deviation_{uuid.uuid4().hex[:8]}"
    alerts = DomainParticipant(int(os.environ["ROS_DOMAIN_ID"]))
    kept = Qos(
        Policy.Reliability.Reliable(10**9), Policy.Durability.TransientLocal, Policy.History.KeepAll
    )
    reader = DataReader(alerts, Topic(alerts, "rt/robotale/alerts", String_), qos=kept)
    watch = [sys.executable, "-m", "robotale", "monitor", str(MODELS / "sequence.bpmn")]
    monitor = subprocess.Popen(
        [*watch, "--robots", "rover", "--log", name, "--silence", "600"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    clock = WallClock()
    bus = DdsBus(clock, node="rover")
    try:
        assert monitor.stderr.readline().startswith("# monitoring "), monitor.stderr.read()
        writer = bus.writer(tag_topic("rover"), TAG_TYPE, KEEP_ALL, "rover")
        # its battery, written by plain cyclonedds as a robot publishes it, again and again:
        # the monitor reads it best-effort (any writer's), so what is written before the
        # monitor has matched this writer is lost, as it would be from a robot
        battery_type = "sensor_msgs/msg/BatteryState"
        battery = DataWriter(alerts, Topic(alerts, "rt/rover/battery", idl_type(battery_type)))
        matched(writer, patience(30))
        matched(battery, patience(30))
        # the labels its engine tags Prepare and Carry On with
        faulty = [("prepare", "start"), ("prepare", "complete"), ("carry_on", "start")]
        stamps = {}
        for activity, lifecycle in faulty:
            stamps[activity] = clock.now()
            tag = Tag(stamps[activity], "rover", activity, lifecycle)
            bus.publish(tag_topic("rover"), tag, msgtype=TAG_TYPE, sender="rover", qos=KEEP_ALL)

        def draining(heard: list[dict]) -> None:
            """30 % (fine) until the deviation is heard, then 15 % (below the threshold)."""
            level = 0.15 if any(a["kind"] == "deviation" for a in heard) else 0.3
            battery.write(to_sample(battery_type, {"percentage": level}))

        # an alert about Prepare or 30 %, were there one, would be here 0.5 s after the others
        heard = alerts_heard(reader, 2, settle=0.5, meanwhile=draining)
        said, complaints = interrupted(monitor)
        stored = live_alerts(neo4j_driver, name)
    finally:
        if monitor.poll() is None:
            monitor.kill()
        delete_live(neo4j_driver, name)
        delete_log(neo4j_driver, name)  # the live run's event knowledge graph
    kinds = sorted((a["kind"], a["robot"]) for a in heard)
    assert kinds == [("battery", "rover"), ("deviation", "rover")], said + complaints
    low, deviation = sorted(heard, key=lambda a: a["kind"])
    assert "15.0 %" in low["text"]
    assert "'carry_on'" in deviation["text"] and "Rover" in deviation["text"]
    # within a second of the tag's stamp on a quiet machine; stretched by the load here
    assert 0 <= deviation["stamp"] - stamps["carry_on"] < patience(1.0)
    assert sorted((a.kind, a.robot, a.text) for a in stored) == sorted(
        (a["kind"], a["robot"], a["text"]) for a in heard
    )
    assert "# alert deviation rover" in said


def test_the_state_apis_pose_is_the_last_odometry_sample_the_monitor_kept_over_dds(
    tmp_path, neo4j_driver
):
    """A rover's odometry written by plain cyclonedds on /rover/odom while ``robotale
    monitor`` watches it (one tag published, so the run has a start): at 6 Hz no sample is
    thrown away by the 10 Hz limit (a best-effort reader may lose one on a busy machine), and
    the dashboard's Mission state API gives, at any moment of the run, the pose of the last
    sample kept at or before it; a burst at 100 Hz is kept at 10 samples a second
    at most, each one a sample written here."""
    import uuid

    from robotale.ekg.live import live_poses
    from robotale.fame_runtime.node import KEEP_ALL
    from robotale.fame_runtime.tags import TAG_TYPE, Tag, tag_topic
    from robotale.webapp import create_app
    from robotale.webapp.settings import WebSettings

    name = f"test_odometry_{uuid.uuid4().hex[:8]}"
    settings = WebSettings(tmp_path / "uploads", tmp_path / "models", secret_key="test")
    client = create_app(settings).test_client()
    watch = [str(MODELS / "sequence.bpmn"), "--robots", "rover", "--silence", "600"]
    clock = WallClock()
    bus = DdsBus(clock, node="rover")
    odometry = DomainParticipant(int(os.environ["ROS_DOMAIN_ID"]))
    written: list[tuple[float, float, float, float]] = []  # stamp, x, y, z

    def write(writer, stamp: float, k: int) -> None:
        sec = int(stamp)
        pose = {"position": {"x": 1.0 * k, "y": -0.5 * k, "z": 0.25}}
        sample = {
            "header": {"stamp": {"sec": sec, "nanosec": round((stamp - sec) * 1e9)}},
            "pose": {"pose": pose},
        }
        writer.write(to_sample(ODOMETRY, sample))
        written.append((sec + round((stamp - sec) * 1e9) / 1e9, 1.0 * k, -0.5 * k, 0.25))

    def stored(count: int, least: int) -> list:
        """The poses stored once ``count`` are, or after a patient wait at least ``least``:
        the monitor reads odometry best-effort (any writer's samples, as robots publish
        them), so a busy machine may drop one on the way, as it would on a robot."""
        deadline = time.monotonic() + patience(30)
        while len(poses := live_poses(neo4j_driver, name)) < count:
            if time.monotonic() > deadline:
                assert len(poses) >= least, (len(poses), count)
                break
            time.sleep(0.1)
        return poses

    with monitored(neo4j_driver, name, watch) as (monitor, _):
        tags = bus.writer(tag_topic("rover"), TAG_TYPE, KEEP_ALL, "rover")
        kept = dds_qos(replace(DEFAULT_QOS, history="keep_all"))
        topic = Topic(odometry, "rt/rover/odom", idl_type(ODOMETRY))
        writer = DataWriter(odometry, topic, qos=kept)
        matched(tags, patience(30))
        matched(writer, patience(30))
        start = clock.now()
        bus.publish(
            tag_topic("rover"),
            Tag(start, "rover", "prepare", "start"),
            msgtype=TAG_TYPE,
            sender="rover",
            qos=KEEP_ALL,
        )
        for k in range(8):
            write(writer, clock.now(), k)
            time.sleep(1 / 6)
        heard = [(p.stamp, p.x, p.y, p.z) for p in stored(8, least=7)]
        # every sample at 6 Hz is kept (none thrown away by the 10 Hz limit), in order; the
        # pose at a moment is that of the last one kept at or before it
        assert all(h in [pytest.approx(w) for w in written] for h in heard), heard
        assert [h[0] for h in heard] == sorted(h[0] for h in heard), heard
        api = f"/api/mission/{name}/{name}/state"
        for a, b in itertools.pairwise([start, *[w[0] for w in written]]):
            t = round((a + b) / 2 - start, 6)  # between two samples
            before = [h for h in heard if h[0] - start <= t]
            pose = client.get(f"{api}?t={t}").json["robots"]["rover"]["pose"]
            if not before:
                assert pose is None, t
            else:
                assert [pose["x"], pose["y"], pose["z"]] == pytest.approx(before[-1][1:]), t
        # a burst: 100 samples stamped 10 ms apart
        burst = clock.now() + 1.0
        for k in range(100):
            write(writer, burst + k / 100, 100 + k)
        time.sleep(patience(2))
        interrupted(monitor)
        poses = live_poses(neo4j_driver, name)
    late = [(p.stamp, p.x, p.y, p.z) for p in poses if p.stamp >= burst - 1e-6]
    assert 1 <= len(late) <= 10, late
    stamps = [p[0] for p in late]
    assert all(b - a >= 0.1 - 1e-6 for a, b in itertools.pairwise(stamps)), stamps
    assert all(p in [pytest.approx(w) for w in written[8:]] for p in late), late


def test_monitor_alerts_a_late_message_and_an_overlong_activity_once_each(tmp_path, neo4j_driver):
    """A rover played here over DDS: of its three messages, the one of type ``report`` no one
    receives within its 1.5 s raises one alert, the received one and the ``chat`` one (30 s
    default) none; its Measure, running longer than the 95th percentile of Measure's durations
    in an earlier run stored in Neo4j (numpy's, from the durations written here), raises one
    alert after that long, its Prepare, shorter than Prepare's, none."""
    import uuid

    import numpy as np
    import pandas as pd

    from robotale.ekg.live import live_alerts
    from robotale.ekg.logs import delete_log
    from robotale.fame_runtime.node import KEEP_ALL
    from robotale.fame_runtime.tags import TAG_TYPE, Tag, tag_topic

    suffix = uuid.uuid4().hex[:8]
    name, earlier = f"test_timing_{suffix}", f"test_earlier_{suffix}"
    measures = [0.5 + 0.15 * i for i in range(10)]
    rows_ = []
    begin = pd.Timestamp("2026-01-01T00:00:00Z")
    for i, measure in enumerate(measures):
        at = begin + pd.Timedelta(minutes=i)
        spans = [("prepare", at, 3.0), ("measure", at + pd.Timedelta(seconds=3), measure)]
        for activity, start, seconds in spans:
            end = start + pd.Timedelta(seconds=seconds)
            rows_ += [(f"run{i}", start, activity, "start"), (f"run{i}", end, activity, "complete")]
    csv = tmp_path / "earlier.csv"
    frame = pd.DataFrame(rows_, columns=["case", "time", "activity", "lifecycle"])
    frame.assign(robot="rover").to_csv(csv, index=False)
    assert main(["ingest", str(csv), "--log", earlier, "--replace"]) == 0
    limit = float(np.percentile(measures, 95))

    watch = [str(MODELS / "sequence.bpmn"), "--robots", "rover", "--silence", "600"]
    watch += ["--durations-from", earlier, "--message-timeout", "30"]
    watch += ["--message-timeout", "report=1.5"]
    clock = WallClock()
    bus = DdsBus(clock, node="rover")

    def tag(activity, lifecycle, msg_id="", role=""):
        stamp = clock.now()
        sent = Tag(stamp, "rover", activity, lifecycle, msg_id, role)
        bus.publish(tag_topic("rover"), sent, msgtype=TAG_TYPE, sender="rover", qos=KEEP_ALL)
        return stamp

    try:
        with monitored(neo4j_driver, name, watch) as (monitor, reader):
            writer = bus.writer(tag_topic("rover"), TAG_TYPE, KEEP_ALL, "rover")
            matched(writer, patience(30))
            tag("prepare", "start")
            time.sleep(0.2)
            tag("prepare", "complete")
            measured = tag("measure", "start")
            sent = {
                m: tag(kind, "start", m, "send") for m, kind in [("m1", "report"), ("m2", "report")]
            }
            tag("chat", "start", "m3", "send")
            tag("listen", "start", "m2", "receive")
            # a second alert of either kind, were there one, would be here 2 s after the first
            heard = alerts_heard(reader, 2, settle=2.0)
            said, complaints = interrupted(monitor)
            stored = live_alerts(neo4j_driver, name)
    finally:
        delete_log(neo4j_driver, earlier)
    assert sorted(a["kind"] for a in heard) == ["duration", "message"], said + complaints
    long, late = sorted(heard, key=lambda a: a["kind"])
    assert "message m1 ('report') sent by rover" in late["text"], late
    assert "within 1.5 s" in late["text"]
    assert 1.5 <= late["stamp"] - sent["m1"] < 1.5 + patience(1.0)
    assert "'measure'" in long["text"] and f"{limit:.1f} s" in long["text"], long
    assert limit <= long["stamp"] - measured < limit + patience(1.0)
    assert sorted((a.kind, a.text) for a in stored) == sorted((a["kind"], a["text"]) for a in heard)


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_the_live_log_is_the_prepared_recording_and_the_state_api_answers_on_it_mid_run(
    tmp_path, neo4j_driver
):
    """``robotale monitor`` beside a ``fame run --bus dds --record`` of the agri mission: while
    the run goes on, the dashboard's Mission API answers on the growing live log, and a Cypher
    count of the live log's events in the graph grows while the registry lists it as live;
    when it has ended, the live log's events are, row by row, those ``prepare`` makes of the
    run's bag (robot, activity, lifecycle, message, order and time), its graph is the one
    ``robotale ingest`` builds of the bag (every event with its properties, CORR, DF, COMM,
    OBSERVED, DF_C and BEGINS edge; the case's name aside), and the Mission API on the
    ingested bag answers at the times asked mid-run as the live log did."""
    import subprocess
    import sys
    import uuid

    import pandas as pd
    from ekg_graph import graph
    from live_logs import assert_prepared

    from robotale.ekg.live import live_tags
    from robotale.ekg.logs import delete_log, list_logs, log_info, stored_events
    from robotale.eventlog.preparing import prepare_recordings
    from robotale.results.live import live_count, live_events
    from robotale.webapp import create_app
    from robotale.webapp.settings import WebSettings

    suffix = uuid.uuid4().hex[:8]
    name, stored = f"test_live_{suffix}", f"test_prepared_{suffix}"
    settings = WebSettings(tmp_path / "uploads", tmp_path / "models", secret_key="test")
    client = create_app(settings).test_client()
    robots = "drone,tractor_1"
    bag = tmp_path / "run"
    skills = str(MODELS / "agri_skills.py")
    run = [sys.executable, "-m", "robotale", "fame", "run", str(AGRI), "--robots", robots]
    run += ["--skills", skills, "--bus", "dds", "--record", str(bag), "--until", "60"]
    # (tags stored before the look, the state API's answer) mid-run
    asked: list[tuple[int, dict]] = []
    counted: list[int] = []  # the live log's events in the graph, mid-run
    statuses: set[str] = set()
    api = f"/api/mission/{name}/{name}"

    def count() -> None:
        """The live log's events in the graph now, and once there are some what the registry
        says of it (the monitor still runs whenever this is called)."""
        counted.append(stored_events(neo4j_driver, name))
        if counted[-1] and not statuses:
            statuses.add(next(g["status"] for g in list_logs(neo4j_driver) if g["name"] == name))

    with monitored(neo4j_driver, name, [str(AGRI), "--robots", robots]) as (monitor, _):
        fame = subprocess.Popen(run, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            while fame.poll() is None:
                time.sleep(0.5)
                count()
                held = live_count(neo4j_driver, name)
                summary = client.get(api)
                if summary.status_code != 200:  # no tag stored yet
                    continue
                assert summary.json["live"] is True
                t = round(summary.json["duration"] * 0.9, 3)
                state = client.get(f"{api}/state?t={t}")
                assert state.status_code == 200, state.json
                asked.append((held, state.json))
            complaints = fame.communicate(timeout=patience(60))[1]
            assert fame.returncode == 0, complaints
            prepared = prepare_recordings(bag)  # the bag is whole once its run ended
            # the robots are done and the monitor still runs: its last appends come in (the
            # first append of a busy machine's Neo4j plans every query, which takes seconds;
            # a loaded machine's monitor may pause longer than any wait for the count to stay
            # put, so the wait is for every event of the recording)
            deadline = time.monotonic() + patience(60)
            while time.monotonic() < deadline and counted[-1:] != [len(prepared)]:
                time.sleep(0.5)
                count()  # a loaded machine's monitor may store its first events only now
        finally:
            if fame.poll() is None:
                fame.kill()
        heard = live_tags(neo4j_driver, name)  # in the order the monitor heard them
        interrupted(monitor)
        events = live_events(neo4j_driver, name)
        assert log_info(neo4j_driver, name)["status"] == "complete"
        live_graph = graph(neo4j_driver, name, case=name)
    assert_prepared(events, prepared)
    assert main(["ingest", str(bag), "--log", stored, "--replace"]) == 0
    try:
        assert live_graph == graph(neo4j_driver, stored, case=bag.name)
        assert len(live_graph["events"]) == len(prepared)
        grown = [n for n in counted if n]
        assert len(set(grown)) >= 2 and grown == sorted(grown), counted
        assert grown[-1] == len(prepared)  # all in while the monitor still ran
        assert statuses == {"live"}
        # the answers mid-run grew with the run, and are those on the stored recording at the
        # same moment (its time since the stored run's start: a live run starts at the first
        # tag heard so far, which a robot heard late may still move back); compared where the
        # live run held, when asked, every tag stamped by then (one robot's tags may reach the
        # monitor later than another's, by more than the tenth of the run asked before its
        # end on a loaded machine: the live answer was then on less than the recording)
        assert len(asked) >= 3 and asked[0][1]["duration"] < asked[-1][1]["duration"]
        start = pd.Timestamp(client.get(f"/api/mission/{stored}/{bag.name}").json["start"])
        whole = [(held, live) for held, live in asked if _held_by(heard, held, live["time"])]
        assert len(whole) >= 3, (len(asked), len(whole))
        for _, live in whole:
            t = (pd.Timestamp(live["time"]) - start).total_seconds()
            answer = client.get(f"/api/mission/{stored}/{bag.name}/state?t={t}").json
            for robot in live["robots"]:
                mine, theirs = live["robots"][robot], answer["robots"][robot]
                assert mine["activities"] == theirs["activities"], (t, robot)
                assert (mine["last_message"] or {}).get("msg_id") == (
                    theirs["last_message"] or {}
                ).get("msg_id"), (t, robot)
    finally:
        delete_log(neo4j_driver, stored)


def _held_by(heard: list, held: int, moment: str) -> bool:
    """Whether the first ``held`` of the tags ``heard`` (in the order heard) are all those
    stamped at or before ``moment`` (ISO time), and more."""
    import pandas as pd

    at = pd.Timestamp(moment).timestamp() + 1e-6  # a stamp rounded to the microsecond
    return all(i < held for i, tag in enumerate(heard) if tag.stamp <= at)


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_a_robot_killed_mid_run_raises_a_silence_alert_and_leaves_the_live_log_whole(
    neo4j_driver,
):
    """The agri mission's robots as two ``fame node`` processes, watched by ``robotale
    monitor --silence 3``: once the tractor's first tags are stored, its process is killed
    (SIGKILL, no goodbye). The monitor calls the tractor silent once, within 3 s of the kill
    (stretched by the load); the tractor's stored tags are the ones its process printed, in
    its order (the one it was printing when killed aside); the live log stays readable as an
    event log."""
    import signal
    import subprocess
    import sys
    import uuid

    from robotale.ekg.live import live_tags
    from robotale.results.live import live_events

    name = f"test_killed_{uuid.uuid4().hex[:8]}"
    robots = "drone,tractor_1"
    node = [sys.executable, "-m", "robotale", "fame", "node", str(AGRI), "--robots", robots]
    node += ["--skills", str(MODELS / "agri_skills.py"), "--until", "120"]
    with monitored(neo4j_driver, name, [str(AGRI), "--robots", robots, "--silence", "3"]) as (
        monitor,
        reader,
    ):
        nodes = {
            robot: subprocess.Popen(
                [*node, "--robot", robot], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
            )
            for robot in robots.split(",")
        }
        try:
            deadline = time.monotonic() + patience(120)
            while time.monotonic() < deadline:
                stored = [t for t in live_tags(neo4j_driver, name) if t.robot == "tractor_1"]
                if len(stored) >= 3:
                    break
                time.sleep(0.1)
            assert len(stored) >= 3, (
                nodes["tractor_1"].stderr.read() if nodes["tractor_1"].poll() else ""
            )
            # the monitor's clock is the wall clock: its alerts after this are about the kill
            killed = time.time()
            nodes["tractor_1"].send_signal(signal.SIGKILL)
            printed = rows(nodes["tractor_1"].communicate(timeout=patience(60))[0])
            heard: list = []
            deadline = time.monotonic() + patience(30)
            while not heard and time.monotonic() < deadline:
                heard = [
                    a
                    for a in alerts_heard(reader, 1, settle=0.5)
                    if a["robot"] == "tractor_1" and a["stamp"] > killed
                ]
            interrupted(monitor)
            stored = [t for t in live_tags(neo4j_driver, name) if t.robot == "tractor_1"]
            events = live_events(neo4j_driver, name)
        finally:
            for run in nodes.values():
                if run.poll() is None:
                    run.kill()
    assert nodes["tractor_1"].returncode == -signal.SIGKILL
    assert [a["kind"] for a in heard] == ["silence"], heard
    assert heard[0]["stamp"] < killed + 3 + patience(2.0)
    fields = [(t.activity, t.lifecycle) for t in stored]
    said = [(r[2], r[3]) for r in printed if r[1] == "tractor_1"]
    shorter = min(len(fields), len(said))
    assert fields[:shorter] == said[:shorter] and abs(len(fields) - len(said)) <= 1, (fields, said)
    mine = events[events["robot"] == "tractor_1"]
    tagged = mine[mine["lifecycle:state"] != "inprogress"]
    assert tagged["source_index"].tolist() == list(range(len(stored)))
    assert mine["time:timestamp"].is_monotonic_increasing
