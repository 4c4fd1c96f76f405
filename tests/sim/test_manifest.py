"""The run manifest: written whole by the simulator, read back by everyone who reads runs."""

from __future__ import annotations

import json

import pytest

from robotale.errors import InputError
from robotale.fame_runtime.manifest import MANIFEST, read_manifest, read_manifests, write_manifest


def test_a_manifest_reads_back_as_written(tmp_path):
    manifest = {"case": "run_0001", "seed": 7, "outcome": {"status": "ended", "reason": ""}}
    path = write_manifest(tmp_path, manifest)
    assert path == tmp_path / "robotale-run.json" == tmp_path / MANIFEST
    assert json.loads(path.read_text(encoding="utf-8")) == manifest
    assert read_manifest(tmp_path) == manifest
    assert [p.name for p in tmp_path.iterdir()] == ["robotale-run.json"]


def test_runs_without_a_manifest_are_left_out(tmp_path):
    runs = [tmp_path / "run_0001", tmp_path / "run_0002"]
    for run in runs:
        run.mkdir()
    (runs[1] / MANIFEST).write_text('{"robots": {"drone": "Drone"}}')
    assert read_manifest(runs[0]) is None
    assert read_manifests(runs) == {"run_0002": {"robots": {"drone": "Drone"}}}


@pytest.mark.parametrize(
    ("text", "problem"), [("{not json", "is not valid JSON"), ("[1, 2]", "holds no JSON object")]
)
def test_a_broken_manifest_is_one_sentence_naming_the_file(tmp_path, text, problem):
    (tmp_path / MANIFEST).write_text(text)
    with pytest.raises(InputError, match=f"robotale-run.json {problem}"):
        read_manifest(tmp_path)
