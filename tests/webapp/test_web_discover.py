"""The Discover and Perspectives endpoints on the thesis log stored in the real Neo4j, checked
against what the CSV itself says."""

from __future__ import annotations

import base64
import csv
import uuid

import numpy as np
import pytest


@pytest.fixture(scope="module")
def thesis_rows(thesis_csv) -> list[dict[str, str]]:
    with thesis_csv.open(newline="") as stream:
        return list(csv.DictReader(stream))


@pytest.fixture(scope="module")
def stored_thesis(neo4j_driver, thesis_csv):
    """The thesis log stored once for this module, as the dashboard stores it."""
    from robotale.ekg.build import build_ekg
    from robotale.ekg.keys import built_keys
    from robotale.ekg.logs import delete_log
    from robotale.eventlog.readers import read_log

    name = f"test_discover_{uuid.uuid4().hex[:8]}"
    entities = ["robot", "msg_id"]
    build_ekg(
        neo4j_driver,
        read_log(thesis_csv),
        name,
        entities=entities,
        aggregate=built_keys(entities),
        progress=False,
    )
    yield name
    delete_log(neo4j_driver, name)


def values(array) -> list:
    """A plotly JSON array: a list, or a typed array ``{"dtype", "bdata"}`` (base64)."""
    if isinstance(array, dict):
        return np.frombuffer(base64.b64decode(array["bdata"]), dtype=array["dtype"]).tolist()
    return list(array)


def activities(graph: dict) -> set[str]:
    return {n["label"] for n in graph["nodes"] if n["kind"] == "activity"}


def test_values_offered_by_the_filters_are_the_logs(client, stored_thesis, thesis_rows):
    values = client.get(f"/api/discover/values?log={stored_thesis}").json
    assert values["filters"]["robot"] == sorted({r["resource"] for r in thesis_rows})
    assert values["filters"]["activity"] == sorted({r["activity"] for r in thesis_rows})
    assert values["events"] == len(thesis_rows)
    assert sorted(values["entity_types"]) == ["msg_id", "robot"]


def test_dfg_filtered_to_the_drone_has_only_its_activities(client, stored_thesis, thesis_rows):
    graph = client.get(f"/api/discover/dfg?log={stored_thesis}&robot=drone").json
    assert graph["kind"] == "dfg"
    drone = {r["activity"] for r in thesis_rows if r["resource"] == "drone"}
    assert activities(graph) == drone
    assert {n["robot"] for n in graph["nodes"] if n["kind"] == "activity"} == {"drone"}
    # the drone takes off once a day: five runs in the excerpt, each starting the DFG once
    takeoffs = sum(
        1 for r in thesis_rows if r["activity"] == "takeoff" and r["lifecycle"] == "start"
    )
    assert next(n for n in graph["nodes"] if n["label"] == "takeoff")["count"] == takeoffs
    whole = client.get(f"/api/discover/dfg?log={stored_thesis}").json
    assert activities(whole) == {r["activity"] for r in thesis_rows}


def test_a_time_window_keeps_its_events_and_a_garbage_time_is_one_sentence(
    client, stored_thesis, thesis_rows
):
    days = sorted({r["time"][:10] for r in thesis_rows})
    since, until = f"{days[1]}T00:00:00Z", f"{days[1]}T23:59:59Z"
    graph = client.get(f"/api/discover/dfg?log={stored_thesis}&since={since}&until={until}").json
    that_day = {r["activity"] for r in thesis_rows if r["time"][:10] == days[1]}
    assert activities(graph) == that_day
    response = client.get(f"/api/discover/dfg?log={stored_thesis}&since=yesterday-ish")
    assert response.status_code == 400
    assert response.json["error"] == "the start time 'yesterday-ish' is not a date and time."


def test_a_filter_that_matches_nothing_says_what_there_is(client, stored_thesis):
    response = client.get(f"/api/discover/dfg?log={stored_thesis}&robot=ufo")
    assert response.status_code == 400
    assert "no event has robot ufo" in response.json["error"]
    assert "drone" in response.json["error"]


def test_ekg_aggregated_by_activity_and_robot(client, stored_thesis, thesis_rows):
    graph = client.get(f"/api/discover/ekg?log={stored_thesis}&by=robot").json
    classes = [n for n in graph["nodes"] if n["kind"] == "activity"]
    pairs = {(r["activity"], r["resource"]) for r in thesis_rows}
    assert {(n["properties"]["activity"], n["properties"]["robot"]) for n in classes} == pairs
    # a class counts its activity instances, each once by the event that ends it, and its
    # events apart (the thesis' rows are starts and completions)
    events, instances = dict.fromkeys(pairs, 0), dict.fromkeys(pairs, 0)
    for row in thesis_rows:
        events[(row["activity"], row["resource"])] += 1
        instances[(row["activity"], row["resource"])] += row["lifecycle"] != "start"
    shown = {(n["properties"]["activity"], n["properties"]["robot"]): n for n in classes}
    assert {pair: node["count"] for pair, node in shown.items()} == instances
    assert {pair: node["properties"]["events"] for pair, node in shown.items()} == events
    assert {e["entity_type"] for e in graph["edges"]} >= {"robot", "msg_id"}

    only_robots = client.get(f"/api/discover/ekg?log={stored_thesis}&by=robot&edges=robot").json
    assert "msg_id" not in {e["entity_type"] for e in only_robots["edges"]}

    by_activity = client.get(f"/api/discover/ekg?log={stored_thesis}").json
    assert len([n for n in by_activity["nodes"] if n["kind"] == "activity"]) == len(
        {r["activity"] for r in thesis_rows}
    )


def test_spatial_perspective_of_one_class(client, stored_thesis, thesis_rows):
    result = client.get(
        f"/api/perspectives/spatial?log={stored_thesis}&activity=explore&robot=drone"
    ).json
    explore = [r for r in thesis_rows if r["activity"] == "explore" and r["resource"] == "drone"]
    assert result["summary"]["positions"] == len(explore)
    [figure] = result["figures"].values()
    xs = [x for trace in figure["data"] for x in values(trace["x"])]
    assert sorted(xs) == sorted(float(r["x"]) for r in explore)


@pytest.mark.parametrize("name", ["communication", "battery", "performance"])
def test_every_perspective_answers_for_the_whole_log(client, stored_thesis, name):
    result = client.get(f"/api/perspectives/{name}?log={stored_thesis}").json
    assert result["name"] == name
    assert result["figures"] or result["message"]


def test_communication_counts_the_thesis_messages(client, stored_thesis, thesis_rows):
    result = client.get(f"/api/perspectives/communication?log={stored_thesis}").json
    sent = {r["msg_id"] for r in thesis_rows if r["msg_id"] and r["activity"].endswith("!")}
    assert result["summary"]["messages"] == len(sent)


def test_unknown_logs_and_perspectives_are_one_sentence(client, stored_thesis):
    missing = client.get("/api/discover/dfg?log=no_such_log")
    assert (
        missing.status_code == 400
        and "There is no log named 'no_such_log'" in missing.json["error"]
    )
    unknown = client.get(f"/api/perspectives/smell?log={stored_thesis}")
    assert unknown.status_code == 404 and "no 'smell' perspective" in unknown.json["error"]
    nothing = client.get("/api/discover/values?log=")
    assert nothing.status_code == 400 and "Choose a log first" in nothing.json["error"]
