"""One look of a page following a live run (the Mission page's summary with its wait's
checks, the window and the state, as ``live.py`` asks them through Flask's test client) at a
run of one minute and of nine, 20 robots: what a look costs as the run grows, without DDS,
the monitor or Neo4j.

    python benchmarks/live_look.py [--minutes 1 9] [--looks 20] [--rounds 3]

The stored run is in memory: the reader's read of what was stored since its last look
(``live_since``) is answered from a list of tags (20 robots, a tag every 1 to 2 s each, stored
once a second as the monitor stores them) and odometry samples (10 a second each, stored
every tenth of a second); each check of a look's wait moves the clock a tenth of a second on,
so a look waits through the checks that find samples only, as at the live benchmark. The run
is grown to its size by a look every 30 s, then ``--looks`` looks are timed (CPU of this
thread). Each size runs in a process of its own, the sizes interleaved, ``--rounds`` times.
Checked: the last look's summary equals that of a reader that read the whole run at once.
"""

from __future__ import annotations

import argparse
import bisect
import math
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROBOTS = [f"rover_{i}" for i in range(1, 21)]
ACTIVITIES = ("survey", "measure", "report")
START = 1.7e9
NAME = "bench_look"


def stored_run(seconds: float) -> tuple[list, list]:
    """The tags and samples of 20 robots over ``seconds``, in stamp order."""
    from robotale.ekg.live import Pose
    from robotale.fame_runtime.tags import Tag

    tags = []
    for robot in ROBOTS:
        draw = random.Random(robot)
        t = START + draw.uniform(0, 1)
        while t < START + seconds:
            for activity in ACTIVITIES:
                for lifecycle in ("start", "complete"):
                    t += draw.uniform(1.0, 2.0)
                    tags.append(Tag(t, robot, activity, lifecycle))
    tags.sort(key=lambda tag: tag.stamp)
    poses = [
        Pose(START + tick / 10 + j * 1e-4, robot, tick * 0.01, 0.1 * j, 0.0)
        for tick in range(int(seconds * 10))
        for j, robot in enumerate(ROBOTS)
    ]
    return tags, poses


def one(minutes: float, looks: int) -> None:
    """Time ``looks`` looks at a run of ``minutes``; print the CPU median and the check."""
    from robotale.results import live as reading
    from robotale.webapp import create_app, unstored
    from robotale.webapp.views import mission

    end = minutes * 60
    tags, poses = stored_run(end + looks + 5)
    stamps, times = [t.stamp for t in tags], [p.stamp for p in poses]
    clock = {"now": 0.0, "ticking": False}

    def since(_driver, _name, held_tags: int, held_poses: int):
        if clock["ticking"]:  # a check of a look's wait: a tenth of a second later
            clock["now"] += 0.1
        told = bisect.bisect_right(stamps, START + math.floor(clock["now"]))
        sampled = bisect.bisect_right(times, START + clock["now"])
        return tags[held_tags:told], poses[held_poses:sampled]

    reading.live_since = since
    unstored.driver = lambda: None
    mission.CHECK_EVERY = 0.0  # the clock moves at each check instead
    folder = Path(tempfile.mkdtemp(prefix="robotale-bench-look-"))
    client = create_app(upload_dir=folder / "uploads", model_dir=folder / "models").test_client()
    api = f"/api/mission/{NAME}/{NAME}"
    held: dict | None = None

    def look() -> None:
        nonlocal held
        if held is None:
            summary, start = client.get(api).json, 0.0
        else:
            start = max(0.0, held["duration"] - 5.0)
            summary = client.get(f"{api}?since={start}&known={held['events']}&wait=1").json
        events = f"&events={summary['events']}"
        client.get(f"{api}/window?from={start}&to={summary['duration']}{events}")
        client.get(f"{api}/state?t={summary['duration']}{events}")
        held = summary

    while clock["now"] < end:
        clock["now"] = min(clock["now"] + 30.0, end)
        look()
    clock["ticking"] = True
    cpus = []
    for _ in range(looks):
        cpu = time.thread_time()
        look()
        cpus.append(time.thread_time() - cpu)
    clock["ticking"] = False
    grown = client.get(api).json
    reading._kept.pop(NAME, None)
    whole = client.get(api).json
    same = "yes" if grown == whole else "NO"
    print(f"{minutes:g} {1000 * statistics.median(cpus):.1f} {held['events']} {same}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, nargs="+", default=[1.0, 9.0])
    parser.add_argument("--looks", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--one", type=float, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one is not None:
        one(args.one, args.looks)
        return 0
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    found: dict[float, list[float]] = {m: [] for m in args.minutes}
    for _ in range(args.rounds):
        for minutes in args.minutes:
            out = subprocess.run(
                [sys.executable, __file__, "--one", str(minutes), "--looks", str(args.looks)],
                capture_output=True, text=True, check=True,
            ).stdout.split()  # fmt: skip
            found[minutes].append(float(out[1]))
            print(f"  {minutes:g} min ({out[2]} events): look CPU median {out[1]} ms; "
                  f"summary == whole run's: {out[3]}; load {os.getloadavg()[0]:.1f}")  # fmt: skip
    first = statistics.median(found[args.minutes[0]])
    for minutes in args.minutes:
        mid = statistics.median(found[minutes])
        print(f"{minutes:g} min: look CPU median of rounds {mid:.1f} ms ({mid / first:.2f}x)")
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
