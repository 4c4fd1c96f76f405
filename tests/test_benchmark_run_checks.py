"""The same-output checks of ``benchmarks/verify.py`` (every repeat finds what the first
did), ``benchmarks/report.py``'s truth check (as many messages listed as the truth sent) and
the ratios ``benchmarks/peers.py`` prints by wall and by CPU time."""

from pathlib import Path

import pytest
from benchmark_scripts import benchmark

THESIS = Path(__file__).resolve().parents[1] / "examples" / "thesis" / "fame-models" / "fame-ros"


def _findings(model: str):
    verify = benchmark("verify")
    return verify.findings_of(verify.verify_once(THESIS / model, {}))


def test_verifying_a_model_again_finds_the_same():
    verify = benchmark("verify")
    first = _findings("Tractor.bpmn")
    assert first  # the thesis' tractor has findings to compare
    assert verify.differing_findings(first, _findings("Tractor.bpmn")) == ""


def test_a_repeat_that_finds_other_things_differs():
    verify = benchmark("verify")
    first = _findings("Tractor.bpmn")
    other = _findings("Tractor_1.bpmn")  # three findings fewer
    assert verify.differing_findings(first, other) != ""
    assert verify.differing_findings(first, first[:-1]) == (
        f"{len(first)} findings against {len(first) - 1}"
    )
    changed = [*first[:2], (first[2][0], first[2][1] + " (changed)"), *first[3:]]
    assert verify.differing_findings(first, changed).startswith("finding 3: ")


@pytest.mark.parametrize("sent, listed", [(16, 0), (16, 15), (16, 17)])
def test_the_truth_check_says_which_mission_lists_other_messages(sent, listed):
    report = benchmark("report")
    assert report.messages_differ(4, sent, listed) == (
        f"mission 4: the truth sent {sent} messages, robotale lists {listed}"
    )
    assert report.messages_differ(4, sent, sent) == ""


def test_peers_ratios_are_promgs_over_robotales_by_wall_and_by_cpu():
    peers = benchmark("peers")
    ours = peers.Build(2.0, {}, cpu=1.0, server_cpu=3.0)
    theirs = peers.Build(7.0, {}, "2.4.7", 9.0, cpu=2.0, server_cpu=18.0)
    wall, cpu = peers.ratios(ours, theirs)
    assert wall == pytest.approx(3.5)
    assert cpu == pytest.approx(5.0)  # (2 + 18) / (1 + 3): the server's CPU counts on both
