"""The code's layout keeps its promises: commands in one place, every part importing only the
parts above it in the data flow, one owner for each fact, the dashboard's state in its app.

Each check reads the source (its syntax tree) or the objects themselves, so a module that
breaks a rule is named with the line that does.
"""

from __future__ import annotations

import argparse
import ast
import dataclasses
import importlib
import inspect
from collections.abc import Iterator
from pathlib import Path

import pytest

import robotale
from robotale.cli import build_parser
from robotale.errors import ModelError
from robotale.fame_runtime.engine import Engine
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.plan import NodePlan, deploy

PACKAGE = Path(robotale.__file__).parent
#: the parts in the order of the data flow (docs/architecture.md); each may import only those
#: before it
PARTS = [
    "fame_runtime",
    "sim",
    "eventlog",
    "neo4j_server",
    "ekg",
    "discovery",
    "enhancement",
    "results",
    "webapp",
    "commands",
]
MODELS = Path(__file__).parent / "fame_runtime" / "models"


def _modules() -> Iterator[tuple[str, Path, ast.Module]]:
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE.parent).with_suffix("")
        if "cypher" in relative.parts:
            continue
        name = ".".join(relative.parts).removesuffix(".__init__")
        yield name, path, ast.parse(path.read_text(encoding="utf-8"))


MODULES = list(_modules())
NAMES = {name for name, _, _ in MODULES}


def _imports(tree: ast.AST, module: str) -> Iterator[tuple[int, str]]:
    """Every module ``tree`` imports, with its line (``from a import b``: ``a.b`` when ``b``
    is a module, else ``a``)."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from ((node.lineno, alias.name) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative: from the module's own package
                package = module.split(".")[: -node.level]
                base = ".".join([*package, base] if base else package)
            for alias in node.names:
                full = f"{base}.{alias.name}"
                yield node.lineno, full if full in NAMES else base


def _runtime_imports(tree: ast.Module, module: str) -> set[str]:
    """The project's modules ``module`` imports when it runs: at the top and inside functions
    (an import deferred into a function still closes a circle), not those only a type checker
    reads."""
    checked_only = {
        id(node)
        for block in ast.walk(tree)
        if isinstance(block, ast.If) and "TYPE_CHECKING" in ast.unparse(block.test)
        for statement in block.body
        for node in ast.walk(statement)
    }
    kept = ast.Module(
        body=[
            n
            for n in ast.walk(tree)
            if isinstance(n, ast.Import | ast.ImportFrom) and id(n) not in checked_only
        ],
        type_ignores=[],
    )
    return {name for _, name in _imports(kept, module) if name in NAMES}


def _part(module: str) -> str | None:
    bits = module.split(".")
    return bits[1] if len(bits) > 1 and bits[1] in PARTS else None


def _handler_parsers() -> Iterator[tuple[str, argparse.ArgumentParser]]:
    """Every command's parser with the handler ``cli`` hands it to."""
    pending = [build_parser()]
    while pending:
        parser = pending.pop()
        handler = parser.get_default("_handler")
        if handler is not None:
            yield handler, parser
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                pending += list(action.choices.values())


def _handler(dotted: str):
    module, _, name = dotted.rpartition(".")
    return getattr(importlib.import_module(module), name)


def _options(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    skip = (argparse._HelpAction, argparse._VersionAction, argparse._SubParsersAction)
    return [a for a in parser._actions if not isinstance(a, skip) and not a.dest.startswith("_")]


HANDLERS = sorted(_handler_parsers(), key=lambda pair: pair[0])


def test_every_command_of_the_design_has_a_handler_in_the_commands_package():
    modules = {dotted.split(".")[2] for dotted, _ in HANDLERS}
    wanted = {"fame", "simulate", "prepare", "neo4j", "ingest", "discover", "perspectives"}
    assert wanted | {"demo", "serve"} <= modules
    assert all(dotted.startswith("robotale.commands.") for dotted, _ in HANDLERS)
    # `logs` is handled next to `ingest`, as the command that stores logs
    assert {d for d, _ in HANDLERS if d.endswith(("logs_list", "logs_show", "logs_delete"))} == {
        "robotale.commands.ingest.logs_list",
        "robotale.commands.ingest.logs_show",
        "robotale.commands.ingest.logs_delete",
    }


@pytest.mark.parametrize(("dotted", "parser"), HANDLERS, ids=[d for d, _ in HANDLERS])
def test_each_option_is_a_typed_keyword_of_its_handler_and_the_library_owns_its_default(
    dotted, parser
):
    handler = _handler(dotted)
    parameters = inspect.signature(handler).parameters
    forwarded = next((p for p in parameters.values() if p.kind is p.VAR_KEYWORD), None)
    if forwarded is not None:
        # prepare, ingest and annotate hand the preparation options on as PrepareOptions
        from robotale.eventlog.options import PrepareOptions

        parameters = {**inspect.signature(PrepareOptions).parameters, **parameters}
    for action in _options(parser):
        assert action.dest in parameters, f"{dotted} takes no {action.dest!r}"
        parameter = parameters[action.dest]
        assert parameter.kind in (parameter.KEYWORD_ONLY, parameter.POSITIONAL_OR_KEYWORD)
        assert parameter.annotation is not inspect.Parameter.empty, f"{action.dest} is untyped"
        assert action.default is None, f"cli gives {dotted}'s {action.dest} a default"
    for parameter in inspect.signature(handler).parameters.values():
        assert "Namespace" not in str(parameter.annotation)


def test_no_part_imports_argparse_the_cli_or_a_command_module():
    found = [
        f"{path}:{line} imports {name}"
        for module, path, tree in MODULES
        if _part(module) != "commands" and module not in ("robotale.cli", "robotale.__main__")
        for line, name in _imports(tree, module)
        if name == "argparse" or name.startswith(("robotale.commands", "robotale.cli"))
    ]
    assert found == []


def test_no_command_module_imports_another():
    # what two commands share lives in the part that owns it, below the commands
    found = [
        f"{path} imports {name}"
        for module, path, tree in MODULES
        if _part(module) == "commands" and module != "robotale.commands"
        for name in _runtime_imports(tree, module)
        if _part(name) == "commands" and name not in (module, "robotale.commands")
    ]
    assert found == []


def test_each_part_imports_only_the_parts_before_it_in_the_flow():
    found = [
        f"{path}:{line} ({_part(module)}) imports {name}"
        for module, path, tree in MODULES
        if _part(module) is not None
        for line, name in _imports(tree, module)
        if _part(name) is not None and PARTS.index(_part(name)) > PARTS.index(_part(module))
    ]
    assert found == []


def test_modules_import_each_other_without_cycles():
    graph = {name: _runtime_imports(tree, name) - {name} for name, _, tree in MODULES}
    # The ekg server module, which the connection imports, never imports the connection.
    assert "robotale.neo4j_server.server" in graph["robotale.ekg.connection"]
    state: dict[str, int] = {}  # 1 on the path being walked, 2 done

    def cycle_from(module: str, path: list[str]) -> list[str] | None:
        state[module] = 1
        for imported in sorted(graph[module]):
            if state.get(imported) == 1:
                return [*path, module, imported]
            if imported not in state and (found := cycle_from(imported, [*path, module])):
                return found
        state[module] = 2
        return None

    for module in sorted(graph):
        if module not in state:
            assert cycle_from(module, []) is None


def test_imports_inside_functions_say_why():
    # A function-level import is there for a measured start-up cost or an optional extra,
    # and a comment at it (or on the line above) says which.
    found = []
    for _, path, tree in MODULES:
        lines = path.read_text(encoding="utf-8").splitlines()
        for function in ast.walk(tree):
            if not isinstance(function, ast.FunctionDef | ast.AsyncFunctionDef):
                continue
            for node in ast.walk(function):
                if isinstance(node, ast.Import | ast.ImportFrom) and not _explained(
                    lines, node.lineno
                ):
                    found.append(f"{path}:{node.lineno}: {lines[node.lineno - 1].strip()}")
    assert found == []


def _explained(lines: list[str], lineno: int) -> bool:
    if "#" in lines[lineno - 1]:
        return True
    above = lines[lineno - 2].strip()
    if above.startswith(("import ", "from ")):  # the second of a group: the first explains
        return _explained(lines, lineno - 1)
    return above.startswith("#") or ("#" in above and above.startswith("try:"))


def test_the_webapp_keeps_its_state_in_the_app_and_views_import_no_view():
    for module, path, tree in MODULES:
        if _part(module) != "webapp":
            continue
        assert not any(isinstance(n, ast.Global) for n in ast.walk(tree)), path
        for node in tree.body:  # module-level names bound to something that can change
            if isinstance(node, ast.Assign | ast.AnnAssign) and node.value is not None:
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                mutable = isinstance(node.value, ast.Dict | ast.List | ast.Set) or (
                    isinstance(node.value, ast.Constant) and node.value.value is None
                )
                for target in targets:
                    name = getattr(target, "id", "")
                    assert not (mutable and not name.isupper() and name != "__all__"), (
                        f"{path}:{node.lineno} keeps {name} in the module"
                    )
        if module.startswith("robotale.webapp.views."):
            imported = [name for _, name in _imports(tree, module)]
            assert not [n for n in imported if n.startswith("robotale.webapp.views")], path
    assert not (PACKAGE / "webapp" / "browser.py").exists()  # the tests' browser helper


def _code_strings(tree: ast.Module) -> Iterator[tuple[int, str]]:
    """String constants that are not docstrings."""
    docstrings = {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef)
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Constant)
            and isinstance(node.value, str)
            and id(node) not in docstrings
        ):
            yield node.lineno, node.value


def _holders(predicate) -> set[str]:
    return {
        module
        for module, _, tree in MODULES
        if any(predicate(text) for _, text in _code_strings(tree))
    }


def test_each_fact_is_written_in_one_module():
    assert _holders(lambda t: t == "robotale-run.json") == {"robotale.fame_runtime.manifest"}
    assert _holders(lambda t: "There is no log named" in t) == {"robotale.errors"}
    assert _holders(lambda t: t == "activity,robot") == {"robotale.ekg.keys"}
    # the per-log reads: their queries are run from ekg/logs.py only
    log_queries = {p.stem for p in (PACKAGE.parent / "cypher").glob("ekg_log_*.cypher")}
    reads = log_queries - {
        "ekg_log_begin",
        "ekg_log_finish",
        "ekg_log_add_class_type",
        "ekg_log_set_columns",
        "ekg_log_summary",
    }
    assert _holders(lambda t: t in reads | {"ekg_list_logs"}) == {"robotale.ekg.logs"}
    default_entities = [
        f"{path}:{node.lineno}"
        for module, path, tree in MODULES
        if module != "robotale.ekg.keys"
        for node in ast.walk(tree)
        if isinstance(node, ast.Tuple | ast.List)
        and [getattr(e, "value", None) for e in node.elts] == ["robot", "msg_id"]
    ]
    assert default_entities == []


def test_the_low_battery_level_is_written_once():
    # a battery threshold's default is the shared constant, never a number written again
    written = [
        f"{path}:{default.lineno}"
        for _, path, tree in MODULES
        for node in ast.walk(tree)
        if isinstance(node, ast.arguments)
        for arg, default in [
            *zip(reversed(node.args), reversed(node.defaults), strict=False),
            *zip(node.kwonlyargs, node.kw_defaults, strict=True),
        ]
        if arg.arg == "threshold"
        and isinstance(default, ast.Constant)
        and default.value is not None
    ]
    assert written == []
    assert _holders(lambda t: "(default: 20)" in t) == set()


def test_labels_splitting_and_file_writes_each_have_one_function():
    from robotale import queries
    from robotale.discovery import bpmn_net
    from robotale.ekg import readonly
    from robotale.fame_runtime import check, labels, plan
    from robotale.sim import provides, run
    from robotale.webapp import console, overlay

    assert bpmn_net.element_label is plan.element_label is overlay.element_label
    assert overlay.element_label is labels.element_label
    assert check.catches is plan.catches is provides.catches is labels.catches
    assert provides.THROWING is run.THROWING is check.THROWING is labels.THROWING
    assert console.split_statements is readonly.split_statements is queries.split_statements
    defined = {
        f"{module}.{node.name}"
        for module, _, tree in MODULES
        for node in ast.walk(tree)
        if isinstance(node, ast.FunctionDef) and "split" in node.name and "statement" in node.name
    }
    assert defined == {"robotale.queries.split_statements"}
    renames = [
        f"{path}:{line}"
        for module, path, tree in MODULES
        for line, name in _calls(tree)
        if name in ("os.replace", "os.rename") and module != "robotale.files"
    ]
    assert renames == []


def _calls(tree: ast.Module) -> Iterator[tuple[int, str]]:
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            owner = node.func.value
            if isinstance(owner, ast.Name):
                yield node.lineno, f"{owner.id}.{node.func.attr}"


def _behaviours(obj, seen: set[int]) -> Iterator[str]:
    """The behaviours of every node plan reachable from ``obj`` (called processes, loops,
    sub-processes, boundaries included)."""
    if id(obj) in seen:
        return
    seen.add(id(obj))
    if isinstance(obj, NodePlan):
        yield obj.behaviour
    if dataclasses.is_dataclass(obj) and type(obj).__module__ == plan_module():
        for field in dataclasses.fields(obj):
            yield from _behaviours(getattr(obj, field.name), seen)
    elif isinstance(obj, dict):
        for value in obj.values():
            yield from _behaviours(value, seen)
    elif isinstance(obj, list | tuple):
        for value in obj:
            yield from _behaviours(value, seen)


def plan_module() -> str:
    return NodePlan.__module__


def test_the_engine_runs_each_behaviour_the_deployer_gives_from_its_table():
    behaviours: set[str] = set()
    library = Library(MODELS / "library")
    for model in sorted(MODELS.glob("*.bpmn")):
        for _, process in parse(model).pools():
            try:
                plan = deploy(process, skills=["drive", "take_off", "land"], library=library)
            except ModelError:  # a model of skills this test does not name
                continue
            behaviours |= set(_behaviours(plan, set()))
    # every behaviour the test models get has its entry, and no entry is dead
    assert behaviours == set(Engine._BEHAVIOURS)
    assert "dir(self)" not in inspect.getsource(Engine)
