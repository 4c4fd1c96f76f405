"""Where the dashboard goes once an upload is stored: a recording (a zipped folder of
rosbag2 runs) is replayed on the Mission page, at its first run; a table of events (CSV, XES,
OCEL) keeps the links to its findings and its process."""

from __future__ import annotations

import pandas as pd

from robotale.eventlog.schema import CASE, TIMESTAMP

#: the upload kind of a zipped bag folder (:mod:`robotale.webapp.uploads`)
RECORDING = "zip"


def opened_run(kind: str, log: pd.DataFrame) -> dict[str, str]:
    """``{"mission": case}``: the run of a stored recording the Mission page opens, the one
    that began first (ties: the first in the log); ``{}`` for any other upload."""
    if kind != RECORDING or log.empty or CASE not in log or TIMESTAMP not in log:
        return {}
    first = log[TIMESTAMP].groupby(log[CASE], sort=False).min()
    return {"mission": str(first.idxmin())}
