"""Engine throughput against SpiffWorkflow, and signal latency between engines.

Both engines run the same .bpmn files (written to a temporary folder): a sequence of 10 script
tasks, and a parallel split of 10 script-task branches joined again. For each, the process is
parsed once and then instantiated and run to completion again and again; the figures are
process instances and flow nodes per second, and robotale's throughput as a multiple of
SpiffWorkflow's measured in the same run (target: at least 10x). The sequence runs a second
time with the same scripts in JavaScript (FAME's ``this.environment.variables.value_<i> = <i>
* 2; next();``) in the embedded engine, in turns with the Python sequence and timed in CPU
seconds of this process, so a busy machine slows both alike (target: at least half the
Python throughput); and once more with two assignments per script, one of them a string
(``last = 'task_<i>'``), whose outcome comes back from JavaScript as text instead of as the
one number itself.

Then the latency of a signal: one engine throws ``ping`` once a simulated second, another
catches it; the wall time from the throw to the catching token moving, on the in-process bus
driven by a SimClock run loop (target: median under 100 microseconds).

    .venv/bin/python benchmarks/engine_throughput.py [--seconds 2]
"""

from __future__ import annotations

import argparse
import itertools
import os
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from tqdm import tqdm

from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.engine import Engine
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.plan import deploy

HEADER = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" '
    'id="bench" targetNamespace="http://robotale/bench">\n'
    '<bpmn:process id="bench" isExecutable="true">\n<bpmn:startEvent id="start" />\n'
)
FOOTER = '<bpmn:endEvent id="end" />\n</bpmn:process>\n</bpmn:definitions>\n'
TASKS = 10


#: the same assignment in each script language
SCRIPTS = {
    "python": "value_{i} = {i} * 2",
    "javascript": "this.environment.variables.value_{i} = {i} * 2; next();",
}
#: two assignments, one of a string: JavaScript's outcome then travels as text
TWO_WRITES = {
    "python": "value_{i} = {i} * 2\nlast = 'task_{i}'",
    "javascript": (
        "this.environment.variables.value_{i} = {i} * 2; "
        "this.environment.variables.last = 'task_{i}'; next();"
    ),
}


def script_task(i: int, language: str = "python", scripts: dict[str, str] = SCRIPTS) -> str:
    return (
        f'<bpmn:scriptTask id="task_{i}" name="Task {i}" scriptFormat="{language}">'
        f"<bpmn:script>{scripts[language].format(i=i)}</bpmn:script></bpmn:scriptTask>\n"
    )


def flow(source: str, target: str) -> str:
    return (
        f'<bpmn:sequenceFlow id="f_{source}_{target}" sourceRef="{source}" '
        f'targetRef="{target}" />\n'
    )


def sequential(language: str = "python", scripts: dict[str, str] = SCRIPTS) -> str:
    chain = ["start", *[f"task_{i}" for i in range(TASKS)], "end"]
    body = "".join(script_task(i, language, scripts) for i in range(TASKS))
    return HEADER + body + "".join(flow(a, b) for a, b in itertools.pairwise(chain)) + FOOTER


def parallel() -> str:
    body = '<bpmn:parallelGateway id="split" />\n<bpmn:parallelGateway id="join" />\n'
    body += "".join(script_task(i) for i in range(TASKS))
    flows = flow("start", "split") + flow("join", "end")
    flows += "".join(flow("split", f"task_{i}") + flow(f"task_{i}", "join") for i in range(TASKS))
    return HEADER + body + flows + FOOTER


def rate(run_once: Callable[[], None], seconds: float) -> float:
    """Runs per second of ``run_once``, over at least ``seconds`` of wall time."""
    run_once()  # warm up caches and lazy imports
    count, start = 0, time.perf_counter()
    while True:
        for _ in range(50):
            run_once()
        count += 50
        elapsed = time.perf_counter() - start
        if elapsed >= seconds:
            return count / elapsed


def interleaved(ours: Callable[[], None], theirs: Callable[[], None], seconds: float, rounds: int):
    """Both runners' runs per CPU second and per wall second, measured in turns (A B A B ...,
    ``rounds`` each) so a busy machine slows both alike: medians of each, and the median of
    the CPU ratios."""
    ours(), theirs()  # warm up caches and lazy imports
    turns = [
        (cpu_rate(ours, seconds / rounds), cpu_rate(theirs, seconds / rounds))
        for _ in range(rounds)
    ]
    walls = [(rate(ours, seconds / rounds), rate(theirs, seconds / rounds)) for _ in range(rounds)]
    return (
        statistics.median(a for a, _ in turns),
        statistics.median(b for _, b in turns),
        statistics.median(a / b for a, b in turns),
        statistics.median(a for a, _ in walls),
        statistics.median(b for _, b in walls),
    )


def outcomes(path: Path) -> tuple[dict, dict]:
    """The variables one instance leaves, as robotale and SpiffWorkflow run ``path``."""
    from SpiffWorkflow.bpmn import BpmnWorkflow

    engine = robotale_engine(path)
    engine.start_instance()
    workflow = BpmnWorkflow(spiff_spec(path))
    workflow.do_engine_steps()
    return dict(engine.variables), dict(workflow.data)


def same_outcome(ours: dict, theirs: dict) -> list[str]:
    """The script variables (``value_<i>``, ``last``) the two engines left differently."""
    names = {k for k in set(ours) | set(theirs) if k.startswith("value_") or k == "last"}
    return [f"{k}: {ours.get(k)!r} against {theirs.get(k)!r}" for k in sorted(names)
            if ours.get(k) != theirs.get(k)]  # fmt: skip


def robotale_engine(path: Path) -> Engine:
    clock = SimClock()
    return Engine(
        deploy(parse(path).processes["bench"]),
        robot="bench",
        bus=InProcessBus(clock),
        clock=clock,
        tag_sink=[].append,
    )


def spiff_spec(path: Path):
    from SpiffWorkflow.bpmn.parser import BpmnParser

    parser = BpmnParser()
    parser.add_bpmn_file(str(path))
    return parser.get_spec("bench")


def robotale_runner(path: Path) -> Callable[[], None]:
    engine = robotale_engine(path)

    def run_once() -> None:
        engine.start_instance()
        assert engine.idle

    run_once()
    assert engine.variables[f"value_{TASKS - 1}"] == (TASKS - 1) * 2, "the scripts did not run"
    return run_once


def spiff_runner(path: Path) -> Callable[[], None]:
    from SpiffWorkflow.bpmn import BpmnWorkflow

    spec = spiff_spec(path)

    def run_once() -> None:
        workflow = BpmnWorkflow(spec)
        workflow.do_engine_steps()
        assert workflow.is_completed()

    return run_once


PING = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="ping">
  <bpmn:process id="pinger">
    <bpmn:startEvent id="p_start" />
    <bpmn:exclusiveGateway id="p_loop" />
    <bpmn:intermediateThrowEvent id="p_throw" name="ping">
      <bpmn:signalEventDefinition />
    </bpmn:intermediateThrowEvent>
    <bpmn:intermediateCatchEvent id="p_wait" name="1 s">
      <bpmn:timerEventDefinition><bpmn:timeDuration>PT1S</bpmn:timeDuration></bpmn:timerEventDefinition>
    </bpmn:intermediateCatchEvent>
    <bpmn:sequenceFlow id="p1" sourceRef="p_start" targetRef="p_loop" />
    <bpmn:sequenceFlow id="p2" sourceRef="p_loop" targetRef="p_throw" />
    <bpmn:sequenceFlow id="p3" sourceRef="p_throw" targetRef="p_wait" />
    <bpmn:sequenceFlow id="p4" sourceRef="p_wait" targetRef="p_loop" />
  </bpmn:process>
  <bpmn:process id="ponger">
    <bpmn:startEvent id="q_start" />
    <bpmn:exclusiveGateway id="q_loop" />
    <bpmn:intermediateCatchEvent id="q_catch" name="ping">
      <bpmn:signalEventDefinition />
    </bpmn:intermediateCatchEvent>
    <bpmn:sequenceFlow id="q1" sourceRef="q_start" targetRef="q_loop" />
    <bpmn:sequenceFlow id="q2" sourceRef="q_loop" targetRef="q_catch" />
    <bpmn:sequenceFlow id="q3" sourceRef="q_catch" targetRef="q_loop" />
  </bpmn:process>
</bpmn:definitions>
"""


def cpu_rate(run_once: Callable[[], None], seconds: float) -> float:
    """Runs per CPU second of this process: other work on a shared machine does not count."""
    count, start = 0, time.process_time()
    while time.process_time() - start < seconds:
        for _ in range(20):
            run_once()
        count += 20
    return count / (time.process_time() - start)


def javascript_ratio(
    folder: Path, seconds: float, rounds: int = 5, scripts: dict[str, str] = SCRIPTS
) -> tuple[float, float]:
    """The JavaScript sequence's runs per CPU second and its median ratio to the Python
    sequence's, the two measured in turns so that both see the same machine."""
    runners = {}
    for language in ("python", "javascript"):
        path = folder / f"bench_{language}.bpmn"
        path.write_text(sequential(language, scripts))
        runners[language] = robotale_runner(path)
    pairs = [
        (
            cpu_rate(runners["python"], seconds / rounds),
            cpu_rate(runners["javascript"], seconds / rounds),
        )
        for _ in range(rounds)
    ]
    return statistics.median(js for _, js in pairs), statistics.median(js / py for py, js in pairs)


def signal_latencies(path: Path, count: int) -> list[float]:
    """Wall seconds from each ``ping!`` to the catching token moving in the other engine."""
    definitions = parse(path)
    clock = SimClock()
    bus = InProcessBus(clock)
    thrown: dict[str, float] = {}
    latencies: list[float] = []

    def sink(tag) -> None:
        now = time.perf_counter()
        if tag.activity == "ping!" and tag.lifecycle == "start":
            thrown[tag.msg_id] = now
        elif tag.activity == "ping?" and tag.lifecycle == "complete":
            latencies.append(now - thrown.pop(tag.msg_id))

    for process in ("ponger", "pinger"):
        Engine(
            definitions.processes[process], robot=process, bus=bus, clock=clock, tag_sink=sink
        ).start()
    with tqdm(total=count, desc="signal latency", unit="msg", file=sys.stderr, leave=False) as bar:
        while len(latencies) < count:
            before = len(latencies)
            clock.run(until=clock.now() + 100)
            bar.update(len(latencies) - before)
    return latencies[:count]


def main() -> int:
    arguments = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    arguments.add_argument("--seconds", type=float, default=2.0, help="wall time per measurement")
    arguments.add_argument("--messages", type=int, default=5000, help="signals for the latency")
    options = arguments.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        models = {"sequential, 10 script tasks": (sequential(), TASKS + 2)}
        models["parallel split of 10 branches"] = (parallel(), TASKS + 4)
        print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
        print(f"{'model':32} {'engine':14} {'inst./CPU s':>12} {'inst./wall s':>13} "
              f"{'nodes/CPU s':>12} {'ratio':>7}")  # fmt: skip
        for label, (text, nodes) in tqdm(
            models.items(), desc="throughput", file=sys.stderr, leave=False
        ):
            path = Path(folder) / "bench.bpmn"
            path.write_text(text)
            differences = same_outcome(*outcomes(path))
            ours, spiff, ratio, ours_wall, spiff_wall = interleaved(
                robotale_runner(path), spiff_runner(path), options.seconds * 2, rounds=5
            )
            for engine, cpu, wall in (
                ("robotale", ours, ours_wall),
                ("SpiffWorkflow", spiff, spiff_wall),
            ):
                shown = f"{ratio:6.1f}x" if engine == "robotale" else ""
                print(f"{label:32} {engine:14} {cpu:12.0f} {wall:13.0f} {cpu * nodes:12.0f} "
                      f"{shown:>7}")  # fmt: skip
            check = "same variables" if not differences else f"DIFFERENT: {differences[:3]}"
            print(f"{'':32} (interleaved A B A B, median of 5 CPU ratios; {check})")
        js, ratio = javascript_ratio(Path(folder), options.seconds)
        print(
            f"{'sequential, JavaScript':32} {'robotale':12} {js:12.0f} {js * (TASKS + 2):12.0f} "
            f"{ratio:6.2f}x of Python (target >= 0.5)"
        )
        js, ratio = javascript_ratio(Path(folder), options.seconds, scripts=TWO_WRITES)
        print(
            f"{'sequential, JavaScript, 2 writes':32} {'robotale':12} {js:12.0f} "
            f"{js * (TASKS + 2):12.0f} {ratio:6.2f}x of Python (the same, a number and a string)"
        )
        ping = Path(folder) / "ping.bpmn"
        ping.write_text(PING)
        latencies = signal_latencies(ping, options.messages)
    median = statistics.median(latencies) * 1e6
    p95 = statistics.quantiles(latencies, n=20)[-1] * 1e6
    print(
        f"signal throw -> catch across engines: median {median:.1f} us, p95 {p95:.1f} us "
        f"({len(latencies)} signals; target median < 100 us: {median / 100:.2f} of it)"
    )
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
