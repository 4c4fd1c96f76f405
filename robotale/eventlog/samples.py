"""The samples of a perspective (odometry, battery ...) read from a run, and the warnings of
perspectives or robots without any."""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.bagfiles import TIME, namespace
from robotale.eventlog.enrich import Perspective, PreparationWarning, robots_without_samples


def perspective_samples(
    run: Path,
    tables: Sequence[tuple[str, pd.DataFrame]],
    perspective: Perspective,
    robots: Sequence[str],
) -> pd.DataFrame:
    columns = [schema.CASE, schema.ROBOT, schema.TIMESTAMP, *perspective.columns]
    parts = []
    for topic, table in tables:
        part = table[[TIME, *perspective.columns]].rename(columns={TIME: schema.TIMESTAMP})
        for column, factor in (perspective.scale or {}).items():
            part[column] = part[column] * factor
        part[schema.CASE] = run.name
        part[schema.ROBOT] = namespace(topic) or only_robot(run, topic, robots)
        parts.append(part[columns])
    if not parts:
        return pd.DataFrame({c: pd.Series(dtype=object) for c in columns}).astype(
            {schema.TIMESTAMP: "datetime64[ns, UTC]"}
        )
    return pd.concat(parts, ignore_index=True)


def only_robot(run: Path, topic: str, robots: Sequence[str]) -> str:
    if len(robots) == 1:
        return robots[0]
    raise InputError(
        f"{run}: {topic} has no namespace, so it cannot be told which of the robots "
        f"({', '.join(robots)}) it belongs to; record it as /<robot>{topic}."
    )


def warn_missing_samples(
    tags: pd.DataFrame, samples: Mapping[str, pd.DataFrame], perspectives: Sequence[Perspective]
) -> None:
    counts = {p.name: len(samples[p.name]) for p in perspectives}
    missing = {p.name: robots_without_samples(tags, samples[p.name]) for p in perspectives}
    say_missing_samples(counts, missing, perspectives)


def say_missing_samples(
    counts: Mapping[str, int],
    missing_robots: Mapping[str, Sequence[str]],
    perspectives: Sequence[Perspective],
) -> None:
    """The warnings of perspectives without samples (``counts``), and of robots with tags
    but no samples (``missing_robots``, ``run/robot``), per perspective."""
    for p in perspectives:
        if not counts[p.name]:
            warnings.warn(
                f"No bag has samples of the {p.name} perspective ({p.topic}), so the log's "
                f"{', '.join(p.columns)} column(s) are empty.",
                PreparationWarning,
                stacklevel=3,
            )
            continue
        missing = sorted(missing_robots[p.name])
        if missing:
            warnings.warn(
                f"{len(missing)} robot(s) have tags but no {p.name} samples ({p.topic}): "
                f"{', '.join(missing[:5])}{', ...' if len(missing) > 5 else ''}.",
                PreparationWarning,
                stacklevel=3,
            )
