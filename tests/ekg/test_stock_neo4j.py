"""The whole-ingest benchmark's stock Neo4j for PromG: its configuration is Neo4j's stock file
with only what the benchmark must change, and its plugins leave the server's classes alone."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest
from benchmark_scripts import benchmark


@pytest.fixture(scope="module")
def stock():
    """``benchmarks/stock_neo4j.py`` (the benchmarks import each other by name, as scripts)."""
    return benchmark("stock_neo4j")


def settings(text: str) -> tuple[dict[str, str], list[str]]:
    """The settings of a neo4j.conf as Neo4j reads them (a later line wins) and its JVM
    options in order."""
    found: dict[str, str] = {}
    jvm: list[str] = []
    for line in text.splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        key, _, value = line.partition("=")
        if key == "server.jvm.additional":
            jvm.append(value)
        else:
            found[key] = value
    return found, jvm


def test_the_stock_file_changes_only_ports_memory_and_apoc(stock):
    text = stock.stock_conf(7001, 7002, heap="3g", pagecache="1g")
    ours, jvm = settings(text)
    theirs, stock_jvm = settings("\n".join(stock.STOCK_LINES))
    # every JVM option of the stock file, in its order, and none added: the launcher's G1
    assert jvm == stock_jvm and "-XX:+UseG1GC" in jvm and "-XX:+AlwaysPreTouch" in jvm
    assert not any("Parallel" in option for option in jvm)
    changed = {key for key in ours if ours[key] != theirs.get(key)}
    assert changed == {
        "server.default_listen_address",
        "server.bolt.listen_address",
        "server.bolt.advertised_address",
        "server.http.listen_address",
        "server.http.advertised_address",
        "server.memory.heap.initial_size",
        "server.memory.heap.max_size",
        "server.memory.pagecache.size",
        "dbms.security.procedures.unrestricted",
    }
    assert ours["server.bolt.listen_address"] == "127.0.0.1:7001"
    assert ours["server.http.listen_address"] == "127.0.0.1:7002"
    # the same memory as robotale's server: heap fixed (initial = max) and the page cache
    assert ours["server.memory.heap.initial_size"] == ours["server.memory.heap.max_size"] == "3g"
    assert ours["server.memory.pagecache.size"] == "1g"
    # what a user leaves as shipped stays: transaction logs kept, usage reports on
    assert ours["db.tx_log.rotation.retention_policy"] == "2 days 2G"
    assert "dbms.usage_report.enabled" not in ours


def jar(path: Path, *names: str) -> Path:
    with zipfile.ZipFile(path, "w") as out:
        for name in names:
            out.writestr(name, b"x")
    return path


def test_a_plugin_leaves_out_only_the_classes_the_servers_lib_has(stock, tmp_path):
    lib = tmp_path / "lib"
    lib.mkdir()
    jar(lib / "commons-lang3.jar", "org/lang/A.class", "module-info.class")
    plugins = tmp_path / "plugins"
    plugins.mkdir()
    bundling = jar(plugins / "apoc.jar", "apoc/P.class", "org/lang/A.class", "module-info.class")
    alone = jar(plugins / "csv.jar", "org/csv/C.class", "module-info.class")

    kept = stock.unshadowed([bundling, alone], lib, tmp_path / "copies")

    assert kept[1] == alone  # nothing in common with lib: the jar itself
    assert kept[0] == tmp_path / "copies" / "apoc.jar"
    assert sorted(zipfile.ZipFile(kept[0]).namelist()) == ["apoc/P.class", "module-info.class"]
    assert len(zipfile.ZipFile(bundling).namelist()) == 3  # the original is not touched


def test_the_installation_is_laid_out_as_neo4js(stock, tmp_path):
    lib = tmp_path / "jars"
    lib.mkdir()
    plugin = jar(tmp_path / "apoc.jar", "apoc/P.class")
    home = tmp_path / "neo4j"

    stock.lay_out(home, lib, [plugin], "server.bolt.enabled=true\n")

    assert (home / "lib").resolve() == lib.resolve()
    assert (home / "plugins" / "apoc.jar").resolve() == plugin.resolve()
    assert (home / "conf" / "neo4j.conf").read_text() == "server.bolt.enabled=true\n"
    assert "apoc.import.file.enabled=true" in (home / "conf" / "apoc.conf").read_text()
    assert all((home / name).is_dir() for name in ("data", "logs", "import", "run"))


def test_the_pairing_is_said(stock):
    assert "stock neo4j.conf" in stock.describe_pairing("stock", "3g")
    assert "heap 3g" in stock.describe_pairing("stock", "3g")
    assert "robotale's own launch code" in stock.describe_pairing("robotale", "3g")
