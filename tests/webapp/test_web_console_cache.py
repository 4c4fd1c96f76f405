"""The console's kept answers against the real Neo4j: a question asked again on an unchanged
database is answered from memory, and any commit (robotale's ingest and delete, a write from
outside robotale) makes the next answer Neo4j's again. Each answer is compared with the same
query run directly on the driver."""

from __future__ import annotations

from robotale.cli import main
from robotale.ekg import answer_cache
from robotale.ekg.answer_cache import AnswerCache
from robotale.ekg.connection import database
from robotale.ekg.readonly import PlanVerdicts, run_read_only

COUNT = "MATCH (e:Event {log: $log}) RETURN count(e) AS events, collect(DISTINCT e.activity) AS a"


def _console(driver, answers, text, **parameters):
    results = run_read_only(driver, text, parameters, verdicts=PlanVerdicts(), answers=answers)
    return [result.rows for result in results]


def _direct(driver, text, **parameters):
    records, _, _ = driver.execute_query(text, parameters, database_=database())
    return [[list(record.values()) for record in records]]


def _kept_now(driver, answers, text, **parameters):
    """The answer kept for ``text`` at the database's current bookmark (None: none is)."""
    key = answers.key(database(), text, parameters, 1000, 5_000_000)
    with driver.session(database=database()) as session:
        return answers.get(key, answer_cache.mark(session))


def test_an_unchanged_database_answers_from_memory_until_anything_commits(
    neo4j_driver, log_name, tmp_path, capsys
):
    answers = AnswerCache()
    neo4j_driver.execute_query(
        "UNWIND range(1, 5) AS i CREATE (:Event {log: $log, activity: 'a' + i})", log=log_name
    )
    first = _console(neo4j_driver, answers, COUNT, log=log_name)
    assert first == _direct(neo4j_driver, COUNT, log=log_name)
    assert first[0][0][0] == 5
    assert _kept_now(neo4j_driver, answers, COUNT, log=log_name) is not None
    assert _console(neo4j_driver, answers, COUNT, log=log_name) == first

    # a write from outside robotale: the kept answer is no longer valid, Neo4j answers again
    neo4j_driver.execute_query("CREATE (:Event {log: $log, activity: 'b'})", log=log_name)
    assert _kept_now(neo4j_driver, answers, COUNT, log=log_name) is None
    second = _console(neo4j_driver, answers, COUNT, log=log_name)
    assert second == _direct(neo4j_driver, COUNT, log=log_name)
    assert second[0][0][0] == 6

    # robotale's own writes: an ingest of another log, then deleting it
    other = f"{log_name}_other"
    csv = tmp_path / "small.csv"
    csv.write_text(
        "case,activity,timestamp,robot\n"
        + "".join(f"r1,act{i},2024-01-01T00:00:0{i}Z,tb1\n" for i in range(4))
    )
    asked = {"log": other}
    assert _console(neo4j_driver, answers, COUNT, **asked)[0][0][0] == 0
    assert main(["ingest", str(csv), "--log", other, "--pages", "visit"]) == 0
    assert _console(neo4j_driver, answers, COUNT, **asked) == _direct(neo4j_driver, COUNT, **asked)
    assert _console(neo4j_driver, answers, COUNT, **asked)[0][0][0] == 4
    assert main(["logs", "delete", other]) == 0
    assert _console(neo4j_driver, answers, COUNT, **asked)[0][0][0] == 0
    capsys.readouterr()


def test_answers_that_change_by_themselves_are_never_kept(neo4j_driver):
    answers = AnswerCache()
    for text in ("RETURN rand() AS r", "RETURN toString(datetime()) AS now, 1 AS one"):
        before = len(answers)
        _console(neo4j_driver, answers, text)
        assert len(answers) == before, text
        assert _kept_now(neo4j_driver, answers, text) is None
    # the same shape without the clock is kept
    _console(neo4j_driver, answers, "RETURN 1 AS one")
    assert len(answers) == 1


def test_different_parameters_limits_and_texts_are_different_answers(neo4j_driver):
    answers = AnswerCache()
    text = "UNWIND range(1, $n) AS i RETURN i"
    assert _console(neo4j_driver, answers, text, n=3) == [[[1], [2], [3]]]
    assert _console(neo4j_driver, answers, text, n=2) == [[[1], [2]]]
    cut = run_read_only(neo4j_driver, text, {"n": 3}, row_limit=1, answers=answers)
    assert (cut[0].rows, cut[0].total, cut[0].cut) == ([[1]], 3, "rows")
    assert _console(neo4j_driver, answers, text + " ", n=3) == [[[1], [2], [3]]]
    assert len(answers) == 4


def test_the_memory_it_keeps_is_bounded(neo4j_driver):
    answers = AnswerCache(entries=3, size=64 * 1024)
    for n in range(1, 7):
        _console(neo4j_driver, answers, "UNWIND range(1, $n) AS i RETURN i", n=n)
    assert len(answers) == 3
    # an answer larger than an eighth of the memory is given, not kept
    big = _console(neo4j_driver, answers, "UNWIND range(1, 900) AS i RETURN i * 1000000 AS v")
    assert len(big[0]) == 900
    assert len(answers) == 3
    assert answers.bytes <= 64 * 1024
