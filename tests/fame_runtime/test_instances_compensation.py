"""Multi-instance instances with their own data, compensation, and scripts that exhaust their
limits: exact traces worked out by hand from the BPMN 2.0 specification (10.3.8 multi-instance,
10.6.5 and 13.5.5 compensation)."""

from pathlib import Path

from fame_suite import pair, run, trace

from robotale.cli import main
from robotale.fame_runtime import javascript, watchdog

CASES = Path(__file__).resolve().parent / "semantics"
ITEMS = {"rover": {"items": [10, 20, 30]}}


def test_parallel_instances_each_see_their_own_item_and_loop_counter():
    mission, tags = run(CASES / "mi_parallel_items.bpmn", variables=ITEMS)
    assert trace(tags) == pair(0, "rover", "visit") * 3
    rover = mission.engines["rover"].variables
    assert rover["lines"] == [
        "item 10 loopCounter 0",
        "item 20 loopCounter 1",
        "item 30 loopCounter 2",
    ]
    # an instance's own variables are gone with it
    assert "item" not in rover and "line" not in rover and "loopCounter" not in rover


def test_an_error_raised_by_the_instance_whose_loop_counter_is_one_is_caught_around_all():
    mission, tags = run(CASES / "mi_parallel_error.bpmn", variables=ITEMS)
    # three instances start; the first completes (fine), the second notes its item and
    # throws "second", which the boundary around the whole activity catches: the third is
    # cancelled and the activity's normal way on (after) is never taken
    assert trace(tags) == [
        *[(0, "rover", "each", "start")] * 3,
        *pair(0, "rover", "fine"),
        (0, "rover", "each", "complete"),
        *pair(0, "rover", "mark"),
        *pair(0, "rover", "second"),
        *pair(0, "rover", "handle"),
    ]
    assert mission.engines["rover"].variables["raised_by"] == 20
    assert not mission.failures and mission.done


def test_parallel_timers_wait_their_own_items_seconds():
    mission, tags = run(
        CASES / "mi_parallel_timers.bpmn", variables={"rover": {"items": [3, 1, 2]}}
    )
    instance = [("wait", "start"), ("wait", "complete"), ("done", "start")]
    instance += [("done", "complete"), ("each", "complete")]
    want = [(0, "rover", "each", "start")] * 3
    for second in (1, 2, 3):
        want += [(second, "rover", *step) for step in instance]
    assert trace(tags) == [*want, *pair(3, "rover", "after")]
    assert mission.clock.now() == 3


def test_compensation_end_event_runs_the_handlers_in_reverse_order_of_completion():
    mission, tags = run(CASES / "compensation_boundary.bpmn")
    done = ["reserve", "charge", "notice", "undo", "refund", "release"]
    assert trace(tags) == [t for name in done for t in pair(0, "rover", name)]
    assert mission.engines["rover"].completed == 1


def test_compensating_a_sub_process_runs_its_compensation_event_sub_process():
    mission, tags = run(CASES / "compensation_event_subprocess.bpmn")
    assert mission.done
    assert trace(tags) == [
        (0, "rover", "work", "start"),
        *pair(0, "rover", "pick"),
        *pair(0, "rover", "place"),
        (0, "rover", "work", "complete"),
        *pair(0, "rover", "undo"),
        (0, "rover", "undo_work", "start"),
        *pair(0, "rover", "undo_start"),
        *pair(0, "rover", "tidy"),
        *pair(0, "rover", "undo_inner"),
        *pair(0, "rover", "unpick"),  # the inner throw compensates the sub-process's pick
        (0, "rover", "undo_work", "complete"),
        *pair(0, "rover", "after"),  # the throw waited for the compensation to be done
    ]


HOG = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="hog">
  <bpmn:error id="any" name="any" />
  <bpmn:process id="rover" isExecutable="true">
    <bpmn:startEvent id="start" />
    <bpmn:scriptTask id="t_hog" name="Hog" scriptFormat="javascript">
      <bpmn:script>var a = [];
        while (true) { a.push("xxxxxxxxxxxxxxxx" + a.length); }
        next();</bpmn:script>
    </bpmn:scriptTask>
    <bpmn:boundaryEvent id="catch_all" attachedToRef="t_hog"><bpmn:errorEventDefinition />
    </bpmn:boundaryEvent>
    <bpmn:task id="caught" name="caught" />
    <bpmn:endEvent id="end" /><bpmn:endEvent id="end2" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="t_hog" />
    <bpmn:sequenceFlow id="f2" sourceRef="t_hog" targetRef="end" />
    <bpmn:sequenceFlow id="f3" sourceRef="catch_all" targetRef="caught" />
    <bpmn:sequenceFlow id="f4" sourceRef="caught" targetRef="end2" />
  </bpmn:process>
</bpmn:definitions>
"""


def test_a_script_exhausting_its_memory_ends_the_instance_as_a_model_error(
    tmp_path, monkeypatch, capsys
):
    # a small limit keeps the test quick; the sentence names it
    monkeypatch.setattr(
        javascript.JavaScript.__init__,
        "__kwdefaults__",
        {"time_limit": javascript.TIME_LIMIT, "memory_limit": 16 * 1024 * 1024},
    )
    ends_as_model_error(
        tmp_path,
        capsys,
        HOG,
        "robot rover: script task t_hog (Hog) ran out of its 16 MiB of memory; the process "
        "instance ended (a model error: no boundary event catches it)",
    )


def ends_as_model_error(tmp_path, capsys, model: str, sentence: str) -> None:
    """``fame run`` of ``model`` ends its one instance with ``sentence``, counted as failed,
    and the error boundary event around the script does not catch it."""
    path = tmp_path / "hog.bpmn"
    path.write_text(model)
    code = main(["fame", "run", str(path), "--until", "10"])
    out, err = capsys.readouterr()
    assert code == 1
    assert "caught" not in out  # no boundary event catches a model error
    assert err.splitlines()[-2:] == [
        next(line for line in err.splitlines() if line.startswith("# done")),
        f"# {sentence}",
    ]
    assert "instances completed: rover 0; failed: rover 1" in err


MI_COMPENSATION = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="mi_comp">
  <bpmn:process id="rover" isExecutable="true">
    <bpmn:startEvent id="start" />
    <bpmn:scriptTask id="load" name="load" scriptFormat="python">
      <bpmn:multiInstanceLoopCharacteristics>
        <bpmn:loopDataInputRef>items</bpmn:loopDataInputRef>
        <bpmn:inputDataItem id="item" />
      </bpmn:multiInstanceLoopCharacteristics>
      <bpmn:script>loaded = loaded + [item]</bpmn:script>
    </bpmn:scriptTask>
    <bpmn:boundaryEvent id="load_comp" attachedToRef="load"><bpmn:compensateEventDefinition />
    </bpmn:boundaryEvent>
    <bpmn:scriptTask id="unload" name="unload" scriptFormat="python" isForCompensation="true">
      <bpmn:script>unloaded = unloaded + [(item, loopCounter)]</bpmn:script>
    </bpmn:scriptTask>
    <bpmn:association id="a1" sourceRef="load_comp" targetRef="unload" />
    <bpmn:intermediateThrowEvent id="undo" name="undo">
      <bpmn:compensateEventDefinition activityRef="load" />
    </bpmn:intermediateThrowEvent>
    <bpmn:endEvent id="end" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="load" />
    <bpmn:sequenceFlow id="f2" sourceRef="load" targetRef="undo" />
    <bpmn:sequenceFlow id="f3" sourceRef="undo" targetRef="end" />
  </bpmn:process>
</bpmn:definitions>
"""


def test_each_instance_is_compensated_with_its_own_data_the_last_completed_first(tmp_path):
    path = tmp_path / "mi_comp.bpmn"
    path.write_text(MI_COMPENSATION)
    variables = {"rover": {"items": [10, 20, 30], "loaded": [], "unloaded": []}}
    mission, tags = run(path, variables=variables)
    rover = mission.engines["rover"].variables
    assert rover["loaded"] == [10, 20, 30]
    # the handler of each instance sees that instance's item and loopCounter
    assert rover["unloaded"] == [(30, 2), (20, 1), (10, 0)]
    names = [t.activity for t in tags if t.lifecycle == "complete"]
    assert names == ["load"] * 3 + ["undo"] + ["unload"] * 3
    assert mission.done


def test_a_python_script_running_past_its_time_limit_ends_the_instance_as_a_model_error(
    tmp_path, monkeypatch, capsys
):
    # a short limit keeps the test quick; the sentence names it
    monkeypatch.setattr(watchdog, "TIME_LIMIT", 0.3)
    looping = HOG.replace('scriptFormat="javascript"', 'scriptFormat="python"').replace(
        """var a = [];
        while (true) { a.push("xxxxxxxxxxxxxxxx" + a.length); }
        next();""",
        "n = 0\nwhile True:\n    try:\n        n += 1\n    except Exception:\n        pass",
    )
    assert "while True:" in looping and "var a" not in looping
    ends_as_model_error(
        tmp_path,
        capsys,
        looping,
        "robot rover: script task t_hog (Hog) ran longer than its time limit of 0.3 s of "
        f"{watchdog.MEASURE}; the process instance ended (a model error: no boundary event "
        "catches it)",
    )
