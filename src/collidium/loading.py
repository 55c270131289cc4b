"""`load`: a preset name or a scenario file, with overrides, to a ready `Simulation`."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from collidium.errors import InputError
from collidium.presets import PRESETS, preset
from collidium.simulation import Simulation

if TYPE_CHECKING:
    from collidium.scenario import Scenario

#: Plain names accepted as overrides of a scenario file, and the fields they stand for.
FILE_ALIASES = {"dt": "run.dt", "time": "run.time", "collisions": "run.collisions", "seed": "seed"}


def load_scenario(source: str | Path, /, **overrides: Any) -> Scenario:
    """The scenario of a preset or a TOML file, with overrides applied and validated.

    Parameters
    ----------
    source : str or Path
        A preset name (see `collidium.presets.presets`) or the path of a ``.toml`` scenario.
    **overrides
        For a preset: its keyword parameters (``n=500``); keys with a dot are scenario field paths
        applied afterwards (``**{"run.dt": 0.002}``). For a file: field paths, and the aliases
        ``dt``, ``time``, ``collisions`` and ``seed``.

    Raises
    ------
    InputError
        Unknown preset or missing file, bad TOML, unknown parameter or field, invalid value.
    """
    # Imported on first use: pydantic's models take about 9 MB of memory, which a script that
    # builds its own `Simulation` does not need.
    from collidium.scenario import Scenario

    dotted = {key: value for key, value in overrides.items() if "." in key}
    plain = {key: value for key, value in overrides.items() if "." not in key}
    if isinstance(source, str) and source in PRESETS:
        scenario = preset(source, **plain)
    elif isinstance(source, Path) or _looks_like_path(source):
        scenario = Scenario.from_toml(source)
        dotted = {FILE_ALIASES.get(key, key): value for key, value in plain.items()} | dotted
    else:
        raise InputError(
            "preset",
            f"unknown preset {source!r}; choose from {', '.join(PRESETS)}, or give a .toml file",
        )
    return scenario.with_overrides(dotted) if dotted else scenario


def load(source: str | Path, /, **overrides: Any) -> Simulation:
    """A `Simulation` built from a preset name or a TOML scenario file, with overrides.

    Examples
    --------
    >>> sim = load("gas", n=500, seed=3)                  # doctest: +SKIP
    >>> sim = load("my.toml", dt=0.005, **{"particles.0.n": 300})  # doctest: +SKIP

    See `load_scenario` for the arguments and errors.
    """
    return load_scenario(source, **overrides).build()


def _looks_like_path(source: str) -> bool:
    return source.endswith(".toml") or "/" in source or "\\" in source or Path(source).is_file()
