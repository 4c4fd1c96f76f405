"""robotale: understand what a team of robots actually did.

BPMN collaborations drive the robots (``robotale.fame_runtime``), simulated robots carry the
missions out (``robotale.sim``), tagged events become event logs (``robotale.eventlog``) and an
Event Knowledge Graph in Neo4j (``robotale.ekg``), which ``robotale.discovery`` and
``robotale.enhancement`` turn into process models and perspectives for ``robotale.webapp``.
"""

import sys

__version__ = "0.1.0"

# pm4py prints a licence banner to stderr when it believes it is imported by a user's script.
# robotale's output is its own, so mark the banner as already shown before anything imports it.
sys._pm4py_welcome_shown = True  # type: ignore[attr-defined]
