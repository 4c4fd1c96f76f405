"""Bags from robotale's own agri simulation prepare to the drone process of the thesis (fig. 7.4).

Runs the real simulator (``robotale simulate``), then the preparation on its bags.
"""

from __future__ import annotations

import pm4py
import pytest

from robotale.cli import main
from robotale.eventlog import schema
from robotale.eventlog.prepare import prepare

pytestmark = pytest.mark.filterwarnings("ignore:Install the optional requirement:UserWarning")


@pytest.fixture
def agri_runs(tmp_path):
    out = tmp_path / "agri"
    status = main(
        ["simulate", "agri", "--runs", "2", "--tractors", "2", "--seed", "1", "--out", str(out)]
    )
    assert status == 0
    return out


@pytest.mark.slow
def test_a_short_agri_simulation_prepares_to_the_drone_taking_off_then_exploring(agri_runs):
    log = prepare(agri_runs)
    assert sorted(log[schema.CASE].unique()) == ["run_0001", "run_0002"]
    drone = pm4py.filter_event_attribute_values(log, schema.ROBOT, {"drone"}, level="event")
    dfg, start, _ = pm4py.discover_dfg(drone)
    assert set(start) == {"take_off"}
    assert ("take_off", "explore") in dfg
    assert drone[schema.STATE].eq(schema.INPROGRESS).any()
    assert drone[[schema.X, schema.Y, schema.Z]].notna().all().all()
    assert drone[schema.BATTERY].between(0, 100).all()
    assert set(log[schema.ROBOT_TYPE]) >= {"Drone", "Tractor"}
    sends = log[log[schema.MSG_ROLE] == schema.SEND]
    receives = log[log[schema.MSG_ROLE] == schema.RECEIVE]
    assert set(receives[schema.MSG_ID]) <= set(sends[schema.MSG_ID])
