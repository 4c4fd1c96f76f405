"""What charging engine time costs the engine itself: a sequence of 10 Python script tasks,
instantiated and run to completion again and again on a SimClock, without an engine cost (the
baseline), with fixed costs (each step then waits for the clock) and with measured costs. The
figures are instances per wall second and each mode's throughput as a fraction of the baseline
measured in the same process. With a cost every step becomes a clock event (the next step is
scheduled at the time the engine is free), which is what it costs; no target is set.

    .venv/bin/python benchmarks/engine_time.py [--seconds 2]
"""

from __future__ import annotations

import argparse
import itertools
import sys
import tempfile
import time
from pathlib import Path

from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.clock import EngineCost, SimClock
from robotale.fame_runtime.engine import Engine
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.plan import deploy

TASKS = 10
MODES = {
    "no engine cost": None,
    "fixed costs": EngineCost(script=0.002, condition=0.0005, step=0.0001),
    "measured x10": EngineCost(measured=10.0),
}


def sequence() -> str:
    tasks = "".join(
        f'<bpmn:scriptTask id="t{i}" scriptFormat="python"><bpmn:script>value_{i} = {i} * 2'
        "</bpmn:script></bpmn:scriptTask>"
        for i in range(TASKS)
    )
    ids = ["s", *(f"t{i}" for i in range(TASKS)), "e"]
    flows = "".join(
        f'<bpmn:sequenceFlow id="f{n}" sourceRef="{a}" targetRef="{b}" />'
        for n, (a, b) in enumerate(itertools.pairwise(ids))
    )
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n<bpmn:definitions '
        'xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="bench">'
        f'<bpmn:process id="sequence"><bpmn:startEvent id="s" />{tasks}<bpmn:endEvent id="e" />'
        f"{flows}</bpmn:process></bpmn:definitions>"
    )


def throughput(plan, cost: EngineCost | None, seconds: float) -> float:
    """Instances run to completion per wall second."""
    clock = SimClock(0.0, engine_cost=cost)
    engine = Engine(plan, robot="bench", bus=InProcessBus(clock), clock=clock)
    done = 0
    began = time.perf_counter()
    while time.perf_counter() - began < seconds:
        engine.start_instance()
        clock.run()
        done += 1
    if engine.completed != done:
        raise SystemExit(f"{engine.completed} of {done} instances completed")
    return done / (time.perf_counter() - began)


def main() -> int:
    arguments = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    arguments.add_argument("--seconds", type=float, default=2.0, help="wall time per mode")
    options = arguments.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "sequence.bpmn"
        path.write_text(sequence(), encoding="utf-8")
        plan = deploy(parse(path).processes["sequence"])
    rates = {name: throughput(plan, cost, options.seconds) for name, cost in MODES.items()}
    baseline = rates["no engine cost"]
    for name, rate in rates.items():
        print(f"{name:<16} {rate:9.0f} instances/s  {rate / baseline:5.2f} of the baseline")
    return 0


if __name__ == "__main__":
    sys.exit(main())
