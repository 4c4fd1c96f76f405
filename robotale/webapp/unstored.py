"""Runs the pages read from elsewhere than a stored log: a recording replayed by ``robotale
serve --bag`` (it hides a stored log of the same name), else a live run ``robotale monitor``
is storing tag by tag."""

from __future__ import annotations

from robotale.results.live import live_replay
from robotale.results.replay import Replay
from robotale.webapp.state import driver, state


def unstored(name: str, holding: int | None = None) -> Replay | None:
    """The replayed recording or the live run named ``name``, or None (a stored log); with
    ``holding``, the live run as it was kept if it holds that many events (see
    :func:`live_replay`)."""
    replay = state().replays.get(name)
    if replay is not None or not name:
        return replay
    return live_replay(driver(), name, holding)
