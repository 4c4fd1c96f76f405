"""The scenarios robotale ships: each is a mission model (``<name>.bpmn``, a BPMN
collaboration following the FAME guidelines) and its world (``<name>.yaml``).

- ``agri``: the running scenario of the thesis (chapter 3, section 5.2): a drone explores a
  field, the closest of the tractors cuts each weed it finds. ``agri.thesis.yaml`` is its
  world calibrated to the thesis' 70 runs (section 7.2), ``simulate agri --thesis``.
- ``rexdingo``: the physical scenario of section 5.3: REX explores and finds a target, DINGO
  drives there and fires.
- ``stop``: the stop-distance experiment of section 5.3.5: a car drives at a wall and is
  stopped by a FAME model or by direct code (its skills: ``stop.py``; the experiment:
  :mod:`robotale.sim.stopping`).
"""

from pathlib import Path

FOLDER = Path(__file__).resolve().parent


def names() -> list[str]:
    """The scenarios shipped, by name (``agri.thesis.yaml`` is a preset of agri, no scenario)."""
    return sorted(p.stem for p in FOLDER.glob("*.yaml") if "." not in p.stem)


def world_file(name: str, preset: str | None = None) -> Path | None:
    """The world file of a shipped scenario (or of its ``preset``: ``agri.thesis.yaml``), or
    None."""
    path = FOLDER / (f"{name}.{preset}.yaml" if preset else f"{name}.yaml")
    return path if path.is_file() else None


def presets(preset: str) -> list[str]:
    """The scenarios that have a world of that preset."""
    return [name for name in names() if world_file(name, preset) is not None]


def model_file(name: str) -> Path:
    """The mission model of a shipped scenario."""
    return FOLDER / f"{name}.bpmn"


def describe(path: Path) -> str:
    """How a manifest names a model or world file: shipped ones by their place in the package
    (``robotale/sim/scenarios/agri.bpmn``) so a recording reads the same on every machine; a
    user's own file by its full path."""
    resolved = Path(path).resolve()
    if resolved.is_relative_to(FOLDER):
        return f"robotale/sim/scenarios/{resolved.relative_to(FOLDER).as_posix()}"
    return str(resolved)
