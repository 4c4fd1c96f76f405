"""The activity instances of a log as pm4py gets them in the tests that hold DF_C against
pm4py's DFG (test-only)."""

from __future__ import annotations

import pandas as pd

from robotale.discovery.instances import FINISHED, START_TIMESTAMP, activity_instances
from robotale.eventlog import schema


def instance_frame(log: pd.DataFrame) -> pd.DataFrame:
    """The activity instances of ``log`` that ended (pm4py's interval log: one row per
    instance, its end as the timestamp), in the order the EKG's chains take them: by the time
    of their end, ties by the position of the ending event in the log. pm4py is given them
    without their start, so its performance DFG measures from end to end as DF_C does."""
    instances = activity_instances(log)
    ended = instances[instances[FINISHED]]
    position = pd.Series(range(len(log)), index=log[schema.EVENT_ID])
    ended = ended.assign(_position=position[ended[schema.EVENT_ID]].to_numpy())
    ended = ended.sort_values([schema.TIMESTAMP, "_position"], kind="stable")
    return ended.drop(columns=[START_TIMESTAMP, "_position"]).reset_index(drop=True)
