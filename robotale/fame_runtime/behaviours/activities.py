"""Activities (BPMN 2.0 section 10.3): tasks, script tasks in Python or JavaScript, call
activities bound to a skill, called processes and sub-processes. Each is tagged as it starts
and ends; one that waits (a skill, a JavaScript callback, a sub-process) has its boundary
events armed meanwhile."""

from __future__ import annotations

import types
from collections.abc import Mapping
from threading import get_ident
from typing import TYPE_CHECKING, Any

from robotale.errors import ModelError
from robotale.fame_runtime import watchdog
from robotale.fame_runtime.behaviours.boundaries import arm_boundaries
from robotale.fame_runtime.behaviours.compensation import compensable
from robotale.fame_runtime.behaviours.errors import script_limit, throw_error
from robotale.fame_runtime.expressions import BpmnError, Compiled
from robotale.fame_runtime.javascript import Completion, ScriptFailure, ScriptLimit
from robotale.fame_runtime.kinds import Run
from robotale.fame_runtime.model import JAVASCRIPT
from robotale.fame_runtime.plan import NodePlan
from robotale.fame_runtime.tags import Lifecycle
from robotale.fame_runtime.tokens import Token
from robotale.fame_runtime.watchdog import MEASURE, ScriptTimeout

if TYPE_CHECKING:
    from robotale.fame_runtime.engine import Engine

#: values a script leaves behind that are not variables (``import math``, functions it defines)
_NOT_VARIABLES = (types.ModuleType, types.FunctionType, type)


def run_task(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    engine.activities.begin(token, node.label)
    engine.data.inputs(node)
    return _completed(engine, token, node)


def run_script(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    engine.activities.begin(token, node.label)
    engine.data.inputs(node)
    script = node.script
    if script is not None and script.language == JAVASCRIPT:
        return _run_javascript(engine, token, node, script)
    if script is not None:
        try:
            _exec(engine, node, script)
        except BpmnError as error:
            throw_error(engine, token, error.name)
            return None
        except MemoryError:
            script_limit(engine, token, node, "ran out of the memory of the Python process")
            return None
        except ScriptTimeout:
            watch = engine.watch
            limit = watch.limit if watch is not None else watchdog.TIME_LIMIT
            script_limit(
                engine, token, node, f"ran longer than its time limit of {limit:g} s of {MEASURE}"
            )
            return None
    return _completed(engine, token, node)


def _completed(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    """An activity that ran at once completed: tagged, remembered for compensation, its
    outputs written, its token on its way."""
    engine.activities.end(token, Lifecycle.COMPLETE)
    compensable(token, node)
    engine.data.outputs(node, {})
    return engine.follow(token, engine.taken(node, first=False))


def _exec(engine: Engine, node: NodePlan, script: Compiled) -> None:
    watch = engine.watch or engine.watching()
    assert script.code is not None  # a Python script: compiled by the deployer
    try:
        with engine.charged("script"):
            # the watchdog's stamp: a fresh tuple per run, told apart by identity
            watch.running = (node, get_ident())
            try:
                exec(script.code, engine.env, engine.variables)
            finally:
                watch.running = None
                if watch.fired:  # the watchdog stopped it, or is about to
                    watch.settle()
    except (BpmnError, MemoryError, ScriptTimeout):
        raise
    except Exception as error:
        raise ModelError(
            f"robot {engine.robot.name}: script task {node.node.describe()} failed: "
            f"{type(error).__name__}: {error}"
        ) from error
    for name in script.writes:
        if isinstance(engine.variables.get(name), _NOT_VARIABLES):
            del engine.variables[name]
    engine.changed(script.writes)


def _run_javascript(
    engine: Engine, token: Token, node: NodePlan, script: Compiled
) -> NodePlan | None:
    """A JavaScript script task completes when it calls ``next``: at once, like a Python
    script, or later from a callback, its token waiting like a skill's meanwhile (with its
    boundary events armed)."""
    generation = token.generation
    javascript = engine.javascript

    def later() -> Completion:
        return _script_done(engine, token, generation)

    try:
        if engine.time is None:  # nothing to charge: the hot path spares the with block
            now = javascript.run_task(script.source, later)
        else:
            with engine.charged("script"):
                now = javascript.run_task(script.source, later)
    except ScriptFailure as failure:
        throw_error(engine, token, f"script task {node.node.describe()}: {failure.text}")
        return None
    except ScriptLimit as limit:
        script_limit(engine, token, node, limit.what)
        return None
    if now is None:
        arm_boundaries(engine, token, node)
        return None
    if now[0] is not None:
        throw_error(engine, token, now[0])
        return None
    return _completed(engine, token, node)


def _script_done(engine: Engine, token: Token, generation: int) -> Completion:
    """What a script task's ``next`` calls once its run has returned: the task completes
    (or throws) in a later step, as a skill's does."""

    def done(error: str | None, _value: Any) -> None:
        outcome = None if error is None else BpmnError(error)
        engine.call(lambda: _skill_done(engine, token, generation, outcome))

    return done


def run_skill(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    engine.activities.begin(token, node.label)
    inputs = engine.data.inputs(node)
    arm_boundaries(engine, token, node)
    generation = token.generation

    def done(outputs: Mapping[str, Any] | BpmnError | None = None) -> None:
        engine.call(lambda: _skill_done(engine, token, generation, outputs))

    try:
        cancel = engine.skills[node.skill](engine.robot, types.MappingProxyType(inputs), done)
    except BpmnError as error:
        throw_error(engine, token, error.name)
        return None
    except Exception as error:
        raise ModelError(
            f"robot {engine.robot.name}: skill {node.skill!r} of call activity "
            f"{node.node.describe()} failed: {type(error).__name__}: {error}"
        ) from error
    if callable(cancel):
        token.waits.append(cancel)
    return None


def _skill_done(
    engine: Engine,
    token: Token,
    generation: int,
    outputs: Mapping[str, Any] | BpmnError | None,
) -> None:
    if not token.alive or token.generation != generation:
        return  # cancelled meanwhile, or called twice
    engine.enter_token(token)
    token.waits.clear()  # the skill ended: nothing to cancel any more
    if isinstance(outputs, BpmnError):
        throw_error(engine, token, outputs.name)
        return
    values = dict(outputs or {})
    engine.data.set(values)
    activity_done(engine, token, values)


def run_call(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    """A called process or a sub-process: its content runs in a scope of its own while the
    token waits at the activity."""
    engine.activities.begin(token, node.label)
    engine.data.inputs(node)
    arm_boundaries(engine, token, node)
    assert node.child is not None  # the deployer gives every call and sub-process its content
    child = engine.open_scope(node.child, token.scope, token)
    for start in node.child.starts:
        engine.push(engine.new_token(child, start), start)
    if not node.child.starts:
        engine.close_scope(child)
    return None


def activity_done(engine: Engine, token: Token, outputs: Mapping[str, Any] | None = None) -> None:
    """A waiting activity (skill, call, sub-process, event sub-process) completed."""
    engine.enter_token(token)
    node = token.node
    child, token.child = token.child, None
    engine.disarm(token)
    engine.activities.end(token, Lifecycle.COMPLETE)
    if node.behaviour == Run.EVENT_SUBPROCESS:
        engine.consume(token)
        return
    compensable(token, node, child)
    engine.data.outputs(node, outputs or {})
    engine.go_on(token, node)
