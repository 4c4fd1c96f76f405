"""The prepared results of a stored log as digests, to tell whether a faster preparation still
prepares the same: every result file the preparation keeps for a build, each canonicalised
(numbers to 30 binary digits, about 9 decimal ones; plotly's packed arrays unpacked; the
log's name replaced) and hashed. Also runnable, to write the digests of the current code into
the fixture:

    python tests/results/prepared.py   (needs NEO4J_URI / NEO4J_PASSWORD of a running Neo4j)
"""

from __future__ import annotations

import base64
import hashlib
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from benchmark_scripts import benchmark
from neo4j import Driver

from robotale.ekg.build import build_ekg
from robotale.ekg.columnar import results_folder
from robotale.ekg.keys import DEFAULT_AGGREGATE
from robotale.results.logdata import current_build

#: the digests of the prepared results of the benchmark's synthetic logs, by size
FIXTURE = Path(__file__).with_name("prepared_digests.json")
SIZES = (10_000, 100_000)
#: binary digits a number keeps in the digest (about 9 decimal ones): sums taken in another
#: order may differ in the last bits, a different result differs long before
BITS = 30


def synthetic_log(events: int) -> pd.DataFrame:
    """The benchmarks' multi-robot log (``benchmarks/ekg_build.py``): robots, messages,
    positions and battery, so every page has something to show."""
    return benchmark("ekg_build").synthetic_log(events)


def store(driver: Driver, log: pd.DataFrame, name: str, aggregate=None) -> None:
    """Store ``log`` (its class graphs by ``aggregate``, default: activity, as the digests
    were written), without preparing its pages."""
    keys = list(aggregate or DEFAULT_AGGREGATE)
    build_ekg(driver, log, name, aggregate=keys, progress=False)


def result_files(driver: Driver, name: str) -> dict[str, bytes]:
    """Every result kept for the current build of ``name``, by file name."""
    folder = results_folder(current_build(driver, name))
    return {path.name: path.read_bytes() for path in sorted(folder.glob("*.json"))}


def digests(files: dict[str, bytes], name: str) -> dict[str, str]:
    """Each result file's digest (see the module docstring)."""
    return {file: digest(json.loads(data), name) for file, data in files.items()}


def digest(value: Any, name: str) -> str:
    text = json.dumps(canonical(value, name), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def canonical(value: Any, name: str) -> Any:
    if isinstance(value, dict):
        if "bdata" in value and "dtype" in value:  # plotly's packed typed array
            array = np.frombuffer(base64.b64decode(value["bdata"]), dtype=value["dtype"])
            if "shape" in value:
                shape = value["shape"]
                array = array.reshape([int(s) for s in str(shape).split(",")])
            return canonical(array.tolist(), name)
        return {key: canonical(item, name) for key, item in value.items()}
    if isinstance(value, list):
        return [canonical(item, name) for item in value]
    if isinstance(value, float):
        if not math.isfinite(value) or value == 0.0:
            return str(value)
        # the mantissa to BITS binary digits: a decimal rounding has its ties exactly where
        # a mean of nanoseconds falls (x.5 ns), and so differs for a difference in the
        # last bit; a binary one has them where times in nanoseconds never fall
        mantissa, exponent = math.frexp(value)
        return [round(mantissa * 2**BITS), exponent]
    if isinstance(value, str):
        return value.replace(name, "<log>") if name in value else value
    return value


def main() -> int:
    from robotale.ekg.connection import session_driver
    from robotale.ekg.logs import delete_log
    from robotale.results.findings import prepare
    from robotale.results.logdata import LogData

    found = {}
    with session_driver() as driver:
        for size in SIZES:
            name = f"prepared_digest_{size}"
            store(driver, synthetic_log(size), name)
            try:
                prepare(driver, LogData(), name)
                found[str(size)] = digests(result_files(driver, name), name)
            finally:
                delete_log(driver, name)
            print(f"{size}: {len(found[str(size)])} results", flush=True)
    FIXTURE.write_text(json.dumps(found, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
