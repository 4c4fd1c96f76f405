"""The Cypher files are found both in this checkout and in an installed robotale."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from robotale.queries import cypher, statements

REPO = Path(__file__).resolve().parents[2]


def test_queries_load_from_the_checkout():
    on_disk = (REPO / "cypher" / "ekg_server_version.cypher").read_text()
    assert cypher("ekg_server_version") == on_disk


def test_statements_split_on_semicolons_and_drop_comments():
    parts = statements("ekg_delete_log")
    # events, attribute changes, entities, classes, aggregates, the aggregates' member lists,
    # steps, the Log node
    assert len(parts) == 8
    assert all(not part.startswith("//") and not part.endswith(";") for part in parts)
    assert parts[-1].startswith("MATCH (l:Log {name: $log})")


@pytest.mark.slow
def test_an_installed_wheel_carries_the_cypher_files(tmp_path):
    source = tmp_path / "src"
    source.mkdir()
    for name in ("pyproject.toml", "setup.py", "README.md", "LICENSE"):
        shutil.copy(REPO / name, source / name)
    for folder in ("robotale", "cypher"):
        shutil.copytree(
            REPO / folder, source / folder, ignore=shutil.ignore_patterns("__pycache__")
        )
    pip = [sys.executable, "-m", "pip", "--disable-pip-version-check", "-q"]
    subprocess.run(
        [*pip, "wheel", "--no-deps", "-w", str(tmp_path / "dist"), str(source)],
        check=True,
        capture_output=True,
    )
    wheel = next((tmp_path / "dist").glob("robotale-*.whl"))
    names = zipfile.ZipFile(wheel).namelist()
    expected = {f"robotale/cypher/{p.name}" for p in (REPO / "cypher").glob("*.cypher")}
    assert expected <= set(names)

    target = tmp_path / "installed"
    subprocess.run(
        [*pip, "install", "--no-deps", "--target", str(target), str(wheel)],
        check=True,
        capture_output=True,
    )
    probe = "import robotale.queries as q; print(q.__file__); print(q.cypher('ekg_server_version'))"
    result = subprocess.run(
        [sys.executable, "-c", probe],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(target)},
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(str(target))
    assert "CALL dbms.components()" in result.stdout
