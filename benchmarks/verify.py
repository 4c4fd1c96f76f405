"""How fast ``robotale fame verify`` explores: states per second and time to verify each model.

The models: robotale's agri collaboration (``robotale/sim/scenarios/agri.bpmn``, with the
simulator's skills and ``weed_found``/``low_battery`` from outside, as the simulation runs it)
and every model of the thesis authors that the engine can deploy (``fame-ros/*.bpmn``,
``fame-ros/tests/*.bpmn``, ``fame-modeler/*.bpmn``, each with its own folder as the library).
Target: each verified in under 10 s.

Each model is verified ``--repeat`` times, interleaved with the baseline: one run of the same
mission in the engine itself, 600 simulated seconds on the in-process bus (what a modeller
would otherwise do to find out). Best of N wall and CPU seconds for both; the findings of
every repeat are checked equal to the first. The load average is printed: on this shared
machine wall times stretch with it, CPU seconds less so, and the target is judged on CPU
seconds (the verifier runs on one core: on a quiet machine that is its wall time).

    .venv/bin/python benchmarks/verify.py [--repeat 3] [--models DIR]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
import time
from pathlib import Path

from robotale.errors import ModelError
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.mission import Mission
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.skills import load_skills
from robotale.fame_runtime.verify import verify

ROOT = Path(__file__).resolve().parent.parent
AGRI = ROOT / "robotale" / "sim" / "scenarios" / "agri.bpmn"
THESIS = ROOT / "examples" / "thesis" / "fame-models"
TARGET = 10.0


def cases(folder: Path) -> list[tuple[str, Path, dict]]:
    skills = load_skills("robotale.sim.skills")
    found = [
        ("agri (robotale)", AGRI, {"skills": skills, "outside": ["weed_found", "low_battery"]})
    ]
    for path in sorted(folder.glob("*/*.bpmn")) + sorted(folder.glob("*/tests/*.bpmn")):
        found.append((str(path.relative_to(folder)), path, {}))
    return found


def timed(work) -> tuple[float, float, object]:
    wall, cpu = time.perf_counter(), time.process_time()
    result = work()
    return time.perf_counter() - wall, time.process_time() - cpu, result


def verify_once(path: Path, options: dict):
    return verify(parse(path), library=Library(path.parent), **options)


def findings_of(verdict) -> list[tuple[str, str]]:
    """What a repeat is checked by: each finding's kind and sentence, in order."""
    return [(finding.kind, finding.sentence) for finding in verdict.findings]


def differing_findings(first: list[tuple[str, str]], other: list[tuple[str, str]]) -> str:
    """Empty when a repeat found what the first did; else the first finding that differs."""
    for number, (one, two) in enumerate(zip(first, other, strict=False), start=1):
        if one != two:
            return f"finding {number}: {one[1]!r} against {two[1]!r}"
    if len(first) != len(other):
        return f"{len(first)} findings against {len(other)}"
    return ""


def engine_once(path: Path, options: dict) -> float:
    skills = options.get("skills")
    mission = Mission(
        parse(path), clock=SimClock(start=0.0), skills=skills, library=Library(path.parent)
    )
    with contextlib.redirect_stdout(io.StringIO()):  # the scripts' console.log lines
        return mission.run(until=600.0)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--models", type=Path, default=THESIS, help="the authors' models")
    args = parser.parse_args()
    print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    header = (
        f"{'model':42} {'states':>7} {'steps':>7} {'wall s':>7} {'cpu s':>7} {'states/s':>9} "
        f"{'engine cpu s':>12} {'findings':>8}  verdict"
    )
    print(header)
    slowest = 0.0
    for name, path, options in cases(args.models):
        try:
            verify_once(path, options)  # deploys: a model the engine refuses is left out
        except ModelError as error:
            reason = str(error).splitlines()[0].replace(f"{path}: ", "").replace(f"{path}:", "")
            print(f"{name:42} not deployable: {reason[:90]}")
            continue
        walls, cpus, engine_cpus, first = [], [], [], None
        for _ in range(args.repeat):  # verifier and engine in turns (A B A B)
            wall, cpu, verdict = timed(lambda p=path, o=options: verify_once(p, o))
            walls.append(wall)
            cpus.append(cpu)
            if first is None:
                first = (verdict, findings_of(verdict))
            elif difference := differing_findings(first[1], findings_of(verdict)):
                print(f"{name}: the findings differ between runs: {difference}", file=sys.stderr)
                return 1
            try:
                engine_cpus.append(timed(lambda p=path, o=options: engine_once(p, o))[1])
            except ModelError:  # a run the engine stops (an uncaught model error)
                engine_cpus.append(float("nan"))
        verdict = first[0]
        best_wall, best_cpu = min(walls), min(cpus)
        slowest = max(slowest, best_cpu)
        rate = verdict.states / best_cpu if best_cpu > 0 else float("inf")
        bound = f" ({verdict.bound})" if verdict.bound else ""
        print(
            f"{name:42} {verdict.states:7d} {verdict.steps:7d} {best_wall:7.2f} {best_cpu:7.2f} "
            f"{rate:9.0f} {min(engine_cpus):12.3f} {len(verdict.findings):8d}  "
            f"{'under' if best_cpu < TARGET else 'OVER'} {TARGET:g} s{bound}"
        )
    print(
        f"slowest model: {slowest:.2f} CPU s (target: each under {TARGET:g} s; the verifier "
        "uses one core, so on a quiet machine its wall time is its CPU time)"
    )
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0 if slowest < TARGET else 1


if __name__ == "__main__":
    sys.exit(main())
