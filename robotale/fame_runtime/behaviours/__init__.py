"""How the engine runs each element: one behaviour per kind of node plan, in one table.

A behaviour runs a token at a node and returns the node it goes to next, or None when the
token waits (a skill, a timer, a join) or is gone. The deployer
(:mod:`robotale.fame_runtime.plan`) gives every node plan the name of its behaviour
(``NodePlan.behaviour``); :data:`BEHAVIOURS` maps that name to the function. The modules beside
this one hold the behaviours by kind of element, and what they share: arming boundary events,
throwing errors, compensation.

A new kind of element: a function in the module of its kind, its entry here, and the deployer
giving nodes of that kind the entry's name.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from robotale.fame_runtime.behaviours import activities, events, gateways, loops
from robotale.fame_runtime.kinds import Run
from robotale.fame_runtime.plan import NodePlan
from robotale.fame_runtime.tokens import Token

if TYPE_CHECKING:
    from robotale.fame_runtime.engine import Engine

#: runs a token at a node (engine, token, node) and returns where it goes next (None: it waits
#: or is gone)
Behaviour = Callable[["Engine", Token, NodePlan], "NodePlan | None"]

#: how a node runs, by the behaviour the deployer gave it (``NodePlan.behaviour``)
BEHAVIOURS: dict[str, Behaviour] = {
    Run.START: events.run_start,
    Run.CATCH: events.run_catch,
    Run.BOUNDARY: events.run_boundary,
    Run.PASS: events.run_pass,
    Run.END: events.run_end,
    Run.TERMINATE: events.run_terminate,
    Run.EVENT_SUBPROCESS: events.run_event_subprocess,
    Run.TASK: activities.run_task,
    Run.SCRIPT: activities.run_script,
    Run.SKILL: activities.run_skill,
    Run.CALL: activities.run_call,
    Run.SUBPROCESS: activities.run_call,  # its content runs like a called process
    Run.LOOP: loops.run_loop,
    Run.EXCLUSIVE_GATEWAY: gateways.run_exclusive,
    Run.PARALLEL_GATEWAY: gateways.run_parallel,
    Run.INCLUSIVE_GATEWAY: gateways.run_inclusive,
    Run.EVENT_BASED_GATEWAY: gateways.run_event_based,
}
