"""notebooks/ekg_queries.ipynb runs from top to bottom against the session's real Neo4j, and
its outputs hold the counts the thesis log gives when counted by hand (here: with csv)."""

from __future__ import annotations

import ast
import csv
from collections import Counter
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOK = Path(__file__).resolve().parent.parent / "notebooks" / "ekg_queries.ipynb"


def tagged_output(notebook, tag: str):
    """The value the cell tagged ``tag`` displays (a Python literal)."""
    for cell in notebook.cells:
        if tag in cell.get("metadata", {}).get("tags", []):
            [result] = [o for o in cell.outputs if o.output_type == "execute_result"]
            return ast.literal_eval(result.data["text/plain"])
    raise AssertionError(f"no cell tagged {tag!r}")


@pytest.fixture(scope="module")
def thesis_rows(thesis_csv) -> list[dict[str, str]]:
    with thesis_csv.open(newline="") as stream:
        return list(csv.DictReader(stream))


@pytest.mark.slow
def test_notebook_runs_and_counts_the_thesis_log(neo4j_server, log_name, monkeypatch, thesis_rows):
    # The kernel inherits this process's environment: NEO4J_URI etc. from the session server.
    monkeypatch.setenv("ROBOTALE_NOTEBOOK_LOG", log_name)
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    assert all(not cell.get("outputs") for cell in notebook.cells if cell.cell_type == "code")
    NotebookClient(
        notebook,
        timeout=300,
        kernel_name="python3",
        resources={"metadata": {"path": NOTEBOOK.parent}},
    ).execute()

    robots = Counter(row["resource"] for row in thesis_rows)
    messages = {row["msg_id"] for row in thesis_rows if row["msg_id"]}
    counts = tagged_output(notebook, "counts")
    assert counts["events"] == len(thesis_rows)
    assert counts["entities:robot"] == len(robots)
    assert counts["entities:msg_id"] == len(messages)
    assert counts["classes:activity"] == len({row["activity"] for row in thesis_rows})
    pairs = {(row["activity"], row["resource"]) for row in thesis_rows}
    assert counts["classes:activity+robot"] == len(pairs)
    # DF per robot: consecutive events of one robot, one fewer than its events.
    assert counts["DF:robot"] == sum(n - 1 for n in robots.values())

    # A message's sends are its `x!` events and its receives its `x?` events (the thesis'
    # convention; select_closest_tractor carries a msg_id without passing a message on).
    sends, receives = Counter(), Counter()
    for row in thesis_rows:
        if row["msg_id"] and row["activity"].endswith("!"):
            sends[row["msg_id"]] += 1
        elif row["msg_id"] and row["activity"].endswith("?"):
            receives[row["msg_id"]] += 1
    comm = sum(sends[m] * receives[m] for m in messages)
    assert counts["COMM"] == comm
    assert sum(tagged_output(notebook, "messages").values()) == comm
    # DF_C counts activity instances, each once by the event that ends it (every instance of
    # this log completes): a robot's steps are one fewer than its completions
    completions = Counter(row["resource"] for row in thesis_rows if row["lifecycle"] == "complete")
    assert tagged_output(notebook, "robot-steps") == {r: n - 1 for r, n in completions.items()}
