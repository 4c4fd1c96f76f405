"""The sites of simulated runs kept for the Mission page's map, read from their manifests and
world files."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
import yaml


def test_a_site_is_the_world_files_places_and_the_manifests_objects(simulated):
    from robotale.results.site import run_sites
    from robotale.sim import scenarios

    runs = simulated
    world = yaml.safe_load(scenarios.world_file("agri").read_text())
    sites = run_sites(runs)
    assert set(sites) == {"run_0001", "run_0002"}
    site = sites["run_0001"]
    assert site["field"] == world["field"]
    assert {b["name"]: [b["x"], b["y"]] for b in site["bases"]} == {
        name: base["position"] for name, base in world["bases"].items()
    }
    manifest = json.loads((runs / "run_0001" / "robotale-run.json").read_text())
    assert site["objects"] == [
        {"kind": o["kind"], "id": o["id"], "x": o["x"], "y": o["y"]}
        for o in manifest["setup"]["objects"]
    ]


def test_a_damaged_manifest_costs_its_run_only(simulated, tmp_path):
    from robotale.results.site import run_sites

    runs = shutil.copytree(simulated, tmp_path / "agri")
    (runs / "run_0002" / "robotale-run.json").write_text("{not json")
    assert set(run_sites(runs)) == {"run_0001"}


def test_a_moved_world_file_leaves_what_the_manifest_says(simulated, tmp_path):
    from robotale.results.site import run_sites

    runs = shutil.copytree(simulated, tmp_path / "agri")
    path = runs / "run_0001" / "robotale-run.json"
    manifest = json.loads(path.read_text())
    path.write_text(json.dumps({**manifest, "world": str(tmp_path / "gone.yaml")}))
    site = run_sites(runs)["run_0001"]
    assert site["field"] is None and site["bases"] == []
    assert len(site["objects"]) == len(manifest["setup"]["objects"]) > 0


@pytest.fixture(scope="module")
def simulated(tmp_path_factory) -> Path:
    """Two runs of agri as the simulator records them (bags, manifests, truth)."""
    from robotale.sim import scenarios
    from robotale.sim.batch import simulate_batch
    from robotale.sim.plans import plans
    from robotale.sim.worldspec import load_world

    out = tmp_path_factory.mktemp("site") / "agri"
    world = load_world(scenarios.world_file("agri"))
    simulate_batch(plans(world, "agri", runs=2, seed=4), out, workers=0)
    return out
