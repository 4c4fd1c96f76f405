"""Loops and multi-instance activities (BPMN 2.0 section 10.3.8): the activity's body runs
once per instance -- one after the other, or all at once when parallel -- each multi-instance
instance with its own ``loopCounter`` and items; the token waits at the activity meanwhile."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

from robotale.errors import ModelError
from robotale.fame_runtime.behaviours.boundaries import arm_boundaries
from robotale.fame_runtime.kinds import LoopKind
from robotale.fame_runtime.plan import LoopPlan, NodePlan
from robotale.fame_runtime.tokens import ABSENT, Frame, LoopRun, Token

if TYPE_CHECKING:
    from robotale.fame_runtime.engine import Engine


def run_loop(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    """Run the activity's body once per instance (all at once when parallel), then leave
    by the activity's flows; the token waits at the activity meanwhile, with its boundary
    events armed, and cancelling it cancels the instances."""
    marker = _looped(node).loop
    items = None if marker.kind == LoopKind.STANDARD else _loop_items(engine, node)
    run = LoopRun(token, node, items)
    if _loop_finished(engine, run, before=True):
        return engine.follow(token, engine.taken(node, first=False))
    arm_boundaries(engine, token, node)
    token.waits.append(lambda: _stop_instances(engine, run))
    count = len(items) if items is not None and marker.kind == LoopKind.PARALLEL else 1
    for _ in range(count):
        _start_instance(engine, run)
    return None


def instance_done(engine: Engine, token: Token, run: LoopRun) -> None:
    """One instance completed: collect its output, then start the next, wait for the
    others or leave the activity."""
    index = run.active.pop(token)
    run.completed += 1
    marker = _looped(run.node).loop
    engine.enter_token(token)  # its output item is in its own frame
    if marker.output_collection and run.items is not None:
        run.outputs[index] = engine.variables.get(marker.output_element)
    if run.items is not None:
        engine.data.set(
            {"nrOfCompletedInstances": run.completed, "nrOfActiveInstances": len(run.active)}
        )
    completion = _loop_finished(engine, run, before=False)  # may read the instance's item
    engine.enter(run.holder.frame)
    if marker.output_collection and run.items is not None:
        # the outputs of the instances that completed, in instance order (as SpiffWorkflow)
        outputs = [run.outputs[i] for i in sorted(run.outputs)]
        engine.data.set({marker.output_collection: outputs})
    if completion:
        holder = run.holder
        engine.disarm(holder)  # cancels the instances a completion condition cut short
        engine.go_on(holder, run.node)
    elif marker.kind != LoopKind.PARALLEL:
        _start_instance(engine, run)


def _looped(node: NodePlan) -> LoopPlan:
    assert node.loop is not None  # the deployer gives every loop node its loop
    return node.loop


def _loop_items(engine: Engine, node: NodePlan) -> list[Any]:
    """The items of a multi-instance activity: its collection's, or ``loopCardinality``
    times None."""
    looped = _looped(node)
    where = f"the multi-instance activity {node.node.describe()}"
    if looped.cardinality is not None:
        count = engine.conditions.value(looped.cardinality, where)
        if not isinstance(count, int | float) or count < 0 or count != int(count):
            raise ModelError(
                f"robot {engine.robot.name}: the loopCardinality of {where} is {count!r}, "
                "not a whole number of instances"
            )
        return [None] * int(count)
    name = looped.loop.collection
    if name not in engine.variables:
        raise ModelError(
            f"robot {engine.robot.name}: {where} runs once per item of the variable "
            f"{name!r}, which is not set"
        )
    collection = engine.variables[name]
    if isinstance(collection, Mapping):
        return list(collection.values())
    if isinstance(collection, str) or not isinstance(collection, Iterable):
        raise ModelError(
            f"robot {engine.robot.name}: {where} runs once per item of the variable "
            f"{name!r}, which holds {type(collection).__name__} {collection!r}, no list"
        )
    return list(collection)


def _start_instance(engine: Engine, run: LoopRun) -> None:
    index = run.next
    run.next += 1
    body = _looped(run.node).body
    token = engine.new_token(run.holder.scope, body)
    token.instance = run
    run.active[token] = index
    if run.items is not None:  # a multi-instance activity: each instance its own frame
        token.frame = Frame(run.holder.frame, _own_variables(run, run.items, index))

    def begin() -> None:
        if token.alive:
            engine.enter_token(token)
            engine.data.set(_instance_variables(run, index))
            engine.advance(token, body)

    engine.call(begin)


def _own_variables(run: LoopRun, items: list[Any], index: int) -> dict[str, Any]:
    """The variables an instance of a multi-instance activity has for itself."""
    marker = _looped(run.node).loop
    own: dict[str, Any] = {"loopCounter": index}
    if marker.element:
        own[marker.element] = items[index]
    if marker.output_element:
        own[marker.output_element] = ABSENT
    return own


def _instance_variables(run: LoopRun, index: int) -> dict[str, Any]:
    """What an instance finds in the variables as it starts (Camunda's names)."""
    marker = _looped(run.node).loop
    values: dict[str, Any] = {"loopCounter": index}
    if run.items is not None:
        values["nrOfInstances"] = len(run.items)
        values["nrOfActiveInstances"] = len(run.active)
        values["nrOfCompletedInstances"] = run.completed
        if marker.element:
            values[marker.element] = run.items[index]
    return values


def _loop_finished(engine: Engine, run: LoopRun, *, before: bool) -> bool:
    """Whether no more instance is to run: a standard loop's maximum reached or its
    condition false (before the first iteration only with ``testBefore``), every item
    done, or a multi-instance completion condition true."""
    looped = _looped(run.node)
    marker = looped.loop
    where = f"the loop of {run.node.node.describe()}"
    if marker.kind == LoopKind.STANDARD or run.items is None:
        if before and not marker.test_before:
            return False
        if marker.maximum is not None and run.completed >= marker.maximum:
            return True
        engine.data.set({"loopCounter": run.completed})
        return looped.condition is not None and not engine.conditions.holds(looped.condition, where)
    if run.completed >= len(run.items):
        return True
    if before or looped.condition is None:
        return False
    return engine.conditions.holds(looped.condition, where)


def _stop_instances(engine: Engine, run: LoopRun) -> None:
    for token in list(run.active):
        token.instance = None  # cancelled, not completed
        engine.cancel(token)
    run.active.clear()
