"""A live run read look by look equals the run made afresh of every tag heard so far, however
the tags were split into the batches the looks found: the reader keeps the run's tables and
makes again only what the new tags touch, and that must change no answer."""

from __future__ import annotations

import random
import threading
import uuid

import pandas as pd
import pytest
from live_logs import recorded_tags

from robotale.enhancement.mission import mission_run
from robotale.fame_runtime.tags import Tag
from robotale.results import live as reading

#: the first tags of the recorded run (`live_logs.RECORDING`), heard one by one: enough for
#: messages, repeats and late tags
HEARD = 90


def batches(tags: list[Tag], seed: int) -> list[list[Tag]]:
    """``tags`` cut at random places into batches of 1 to 25."""
    draw, cut, first = random.Random(seed), [], 0
    while first < len(tags):
        size = draw.randint(1, 25)
        cut.append(tags[first : first + size])
        first += size
    return cut


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_run_grown_look_by_look_equals_the_run_made_of_all_tags_heard(monkeypatch, seed):
    """Over random splits of a recorded run: after each batch, the run the reader grew equals
    :func:`mission_run` of every tag heard (its tables, robots, length, summary whole and
    since a moment, the sorted control times it counts earlier times by, windows and the state
    at moments throughout), and some looks made only the tail again and took the earlier
    control times over."""
    name = f"live_{uuid.uuid4().hex[:8]}"
    stored: list[Tag] = []
    monkeypatch.setattr(
        reading, "live_since", lambda _driver, _log, tags, _poses: (stored[tags:], [])
    )
    remade: list[tuple[int, int]] = []  # (tags made again, tags held) at each making
    carried: list[bool] = []
    tag_frame = reading._tag_frame

    def counted(log, held, heard, chosen):
        remade.append((len(chosen), len(held)))
        return tag_frame(log, held, heard, chosen)

    monkeypatch.setattr(reading, "_tag_frame", counted)
    try:
        for batch in batches(recorded_tags(HEARD, seed), seed):
            stored += batch
            replay = reading.live_replay(None, name)  # type: ignore[arg-type]
            assert replay is not None
            run = replay.run(name)
            # the control times taken over from the last look, not read again of every event
            carried.append("_control_times" in run.__dict__)
            whole = mission_run(reading.tags_events(name, stored), name)
            assert run._control_times.tolist() == whole._control_times.tolist()
            for table in ("events", "instances", "messages", "moments"):
                pd.testing.assert_frame_equal(getattr(run, table), getattr(whole, table), obj=table)
            assert (run.robots, run.duration) == (whole.robots, whole.duration)
            assert run.summary() == whole.summary()
            for fraction in (0.0, 0.5, 0.9, 1.0):
                t = min(round(whole.duration * fraction, 3), whole.duration)
                assert run.summary(t) == whole.summary(t), t
                assert run.state(t) == whole.state(t), t
                assert run.window(t, whole.duration) == whole.window(t, whole.duration), t
            # the events kept stay in one piece: pyarrow's pieces of a column of strings
            # would add up look by look (each slice and take of them costing as many)
            assert max(_pieces(run.events), default=1) == 1
    finally:
        reading._kept.pop(name, None)
    assert any(chosen < held for chosen, held in remade)
    assert any(carried)


def _pieces(table: pd.DataFrame) -> list[int]:
    """How many pieces pyarrow holds each column of strings of ``table`` in."""
    return [
        table[column].array.__arrow_array__().num_chunks
        for column in table.columns
        if isinstance(table[column].array, pd.arrays.ArrowExtensionArray)
    ]


def test_looks_asking_at_once_after_the_store_changed_make_the_run_once(monkeypatch):
    """Eight looks asking at once after tags were stored make the run once between them (the
    reader's own count of makings), and all answer on that run; a look holding the events a
    summary showed answers on the run kept, unread, after more tags were stored, and a look
    without makes the run again of them."""
    name = f"live_{uuid.uuid4().hex[:8]}"
    tags = recorded_tags(40, seed=1)
    stored: list[Tag] = tags[:20]
    monkeypatch.setattr(
        reading, "live_since", lambda _driver, _log, held, _poses: (stored[held:], [])
    )
    try:
        first = reading.live_replay(None, name)  # type: ignore[arg-type]
        assert first is not None and reading.live_builds(name) == 1
        stored += tags[20:30]
        start = threading.Barrier(8)
        answers: list[object] = []

        def look() -> None:
            start.wait()
            answers.append(reading.live_replay(None, name))  # type: ignore[arg-type]

        looks = [threading.Thread(target=look) for _ in range(8)]
        for thread in looks:
            thread.start()
        for thread in looks:
            thread.join()
        assert reading.live_builds(name) == 2
        assert len(answers) == 8 and all(answer is answers[0] for answer in answers)
        shown = answers[0]
        assert isinstance(shown, reading.LiveReplay)
        assert len(shown.events) == len(reading.tags_events(name, stored))
        stored += tags[30:]
        assert reading.live_replay(None, name, len(shown.events)) is shown  # type: ignore[arg-type]
        assert reading.live_builds(name) == 2
        grown = reading.live_replay(None, name)  # type: ignore[arg-type]
        assert grown is not None and reading.live_builds(name) == 3
        whole = mission_run(reading.tags_events(name, stored), name)
        pd.testing.assert_frame_equal(grown.run(name).events, whole.events)
    finally:
        reading._kept.pop(name, None)
