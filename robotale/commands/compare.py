"""``robotale compare``: what changed between two batches of runs, in sentences, tables and
JSON."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from robotale.discovery.output import write_texts
from robotale.enhancement.compare import Comparison, compare_logs
from robotale.errors import InputError
from robotale.results.eventlogs import read_event_log

#: a name ending so is meant as a file, never as a stored log's name
FILE_SUFFIXES = (".csv", ".xes", ".gz")
#: the characters of a subject the table shows
WIDTH = 48
#: the columns of the changes table printed after the sentences
SHOWN = ["measure", "subject", "who", "a", "b", "relative", "q_value", "ranked"]


def compare_command(
    log_a: str,
    log_b: str,
    *,
    mapping: Sequence[str] = (),
    case_column: str | None = None,
    case_gap: str | None = None,
    json_out: Path | None = None,
    top: int = 20,
) -> int:
    """Compare batch ``log_a`` (the reference) with ``log_b``: each an event log file, or
    the name of a log stored in Neo4j when no such file exists."""
    if top < 1:
        raise InputError(f"--top {top}: give how many changes to list, 1 or more.")
    logs = [
        _read(name, mapping=mapping, case_column=case_column, case_gap=case_gap)
        for name in (log_a, log_b)
    ]
    comparison = compare_logs(*logs, names=("A", "B"))
    if json_out is not None:
        write_texts([(json_out, json.dumps(comparison.to_dict(), indent=2))])
    print(comparison_text(comparison, log_a, log_b, top=top))
    return 0


def _read(name: str, **options) -> pd.DataFrame:
    path = Path(name)
    if path.is_file():
        return read_event_log(path, **options)
    if path.suffix.lower() in FILE_SUFFIXES or len(path.parts) > 1:
        raise InputError(f"{name}: there is no such file.")
    return read_event_log(log_name=name)


def comparison_text(comparison: Comparison, log_a: str, log_b: str, *, top: int = 20) -> str:
    """The sentences, then the largest changes as a table."""
    lines = [f"A: {log_a}", f"B: {log_b}", ""]
    lines += [f"- {sentence}" for sentence in comparison.sentences]
    table = comparison.changes[SHOWN].head(top)
    # a variant is a long path: the sentences name it, the table gives its start
    long = table["subject"].str.len() > WIDTH
    table = table.assign(
        subject=table["subject"].where(~long, table["subject"].str.slice(0, WIDTH) + "…")
    )
    lines += ["", f"The {len(table)} largest changes (of {len(comparison.changes)}):"]
    lines.append(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    return "\n".join(lines)
