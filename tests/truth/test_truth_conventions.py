"""Generated batches written in other tools' conventions give the truth's answers, or say why
not: robotale's CSV with its times at +02:00, the rows shuffled (rows of one instant in another
file order), XES (pm4py's writer), exact copies of rows, and a log missing one message type's
receive tags (its messages are then not observed as received, never lost).
"""

from __future__ import annotations

import oracle
import pandas as pd
import pm4py
import pytest

from robotale.enhancement.communication import communication_perspective
from robotale.eventlog import schema
from robotale.eventlog.readers import read_log

CASE, TIME, ACTIVITY = schema.CASE, schema.TIMESTAMP, schema.ACTIVITY
pytestmark = pytest.mark.slow


def _csv(log: pd.DataFrame, path, *, offset: str = "UTC", shuffle: bool = False) -> str:
    table = schema.to_csv_names(log)
    table["time"] = log[TIME].dt.tz_convert(offset).map(lambda t: t.isoformat())
    if shuffle:
        table = table.sample(frac=1.0, random_state=7)
    table.to_csv(path, index=False)
    return path


def _xes(log: pd.DataFrame, path) -> str:
    pm4py.write_xes(log.copy(), str(path), case_id_key=CASE)
    return path


WRITERS = {
    "csv at +02:00": lambda log, folder: _csv(log, folder / "a.csv", offset="Europe/Paris"),
    "csv shuffled": lambda log, folder: _csv(log, folder / "b.csv", shuffle=True),
    "xes (pm4py)": lambda log, folder: _xes(log, folder / "c.xes"),
}


def _answers(log: pd.DataFrame) -> dict:
    table = communication_perspective(log, delay_threshold=0.1).tables["messages"]
    return {
        "sent": sorted(zip(table["case"], table["msg_id"], strict=True)),
        "received": sorted(
            zip(*[table[table["received"]][c] for c in ("case", "msg_id")], strict=True)
        ),
        # never observed as received: lost, or of a type no receive tag shows (unobserved)
        "missing": sorted(
            zip(*[table[~table["received"]][c] for c in ("case", "msg_id")], strict=True)
        ),
        "lost": sorted(zip(*[table[table["lost"]][c] for c in ("case", "msg_id")], strict=True)),
    }


def _truth(generated) -> dict:
    messages = [
        m for s in generated for run in oracle.load_batch(s.batch) for m in oracle.messages(run)
    ]
    return messages


@pytest.fixture(scope="module")
def some(generated):
    return generated[:3]


@pytest.mark.parametrize("convention", list(WRITERS))
def test_a_batch_in_another_convention_gives_the_truths_messages(some, convention, tmp_path):
    for simulated in some:
        read = read_log(WRITERS[convention](simulated.log, tmp_path))
        answers = _answers(read)
        truth = [m for run in oracle.load_batch(simulated.batch) for m in oracle.messages(run)]
        assert answers["sent"] == sorted((m.case, m.msg_id) for m in truth)
        assert answers["received"] == sorted((m.case, m.msg_id) for m in truth if m.delivered)
        missing = sorted((m.case, m.msg_id) for m in truth if not m.delivered)
        assert answers["missing"] == missing and set(answers["lost"]) <= set(missing)


def test_exact_copies_of_rows_do_not_count_twice(some, tmp_path):
    for simulated in some:
        log = simulated.log
        copies = pd.concat([log, log[log["msg_role"] == "send"].head(5)], ignore_index=True)
        read = read_log(_csv(copies, tmp_path / "copies.csv"))
        truth = [m for run in oracle.load_batch(simulated.batch) for m in oracle.messages(run)]
        answers = _answers(read)
        assert answers["sent"] == sorted((m.case, m.msg_id) for m in truth)
        table = communication_perspective(read, delay_threshold=0.1).tables["messages"]
        assert int(table["resends"].sum()) == int(
            communication_perspective(log, delay_threshold=0.1).tables["messages"]["resends"].sum()
        )


def test_without_a_types_receive_tags_its_messages_are_not_called_lost(some, tmp_path):
    """The log says why not: a type whose receives are all missing is unobserved, not lost."""
    for simulated in some:
        log = simulated.log
        receives = log[log["msg_role"] == "receive"]
        if receives.empty:
            continue
        dropped = receives[ACTIVITY].value_counts().index[0]  # the most received type
        untagged = log[log[ACTIVITY] != dropped]
        table = communication_perspective(untagged, delay_threshold=0.1).tables["messages"]
        kind = dropped.rstrip("?")
        of_type = table[table["message_type"].str.rstrip("!?") == kind]
        assert not of_type["lost"].any() and of_type["unobserved"].all()
