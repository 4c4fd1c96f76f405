"""``benchmarks/engine_throughput.py`` checks that robotale and SpiffWorkflow ran the same
scripts to the same variables, and tells a model run otherwise apart."""

from __future__ import annotations

from benchmark_scripts import benchmark


def load():
    return benchmark("engine_throughput")


def test_both_engines_leave_the_same_variables_and_other_scripts_are_told_apart(tmp_path):
    bench = load()
    same = tmp_path / "same.bpmn"
    same.write_text(bench.sequential())
    ours, theirs = bench.outcomes(same)
    assert ours["value_9"] == theirs["value_9"] == 18  # the last script, by hand: 9 * 2
    assert bench.same_outcome(ours, theirs) == []
    other = tmp_path / "other.bpmn"
    other.write_text(bench.sequential(scripts=bench.TWO_WRITES))
    ours_other, _ = bench.outcomes(other)  # robotale ran scripts that also write `last`
    assert bench.same_outcome(ours_other, theirs) == ["last: 'task_9' against None"]
