"""The seed report's configurations as scenarios (DESIGN.md section 3).

Default vessel: a 20 m x 20 m reflecting box centred on the origin; m = 1 kg, r = 0.25 m,
k = 5 N m^2/C^2, dt = 0.01 s, seed 1, run time 10 s (pool-break: 60 s), unless a preset says
otherwise. Every preset is a small function of keyword overrides returning a `Scenario`::

    preset("gas", n=500, seed=3).build().run(time=5.0)
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any, Literal

from collidium.errors import InputError
from collidium.scenario import Scenario

Collisions = Literal["exact", "step", "off"]
Boundary = Literal["reflecting", "periodic"]
PresetFunction = Callable[..., Scenario]

#: Preset name -> function returning its `Scenario`.
PRESETS: dict[str, PresetFunction] = {}

#: Preset name -> (seed report section, one-line description).
_ABOUT: dict[str, tuple[str, str]] = {}


def _preset(
    name: str, section: str, description: str
) -> Callable[[PresetFunction], PresetFunction]:
    """Register a preset function under ``name``."""

    def register(function: PresetFunction) -> PresetFunction:
        PRESETS[name] = function
        _ABOUT[name] = (section, description)
        return function

    return register


def _scenario(
    name: str,
    particles: list[dict[str, Any]],
    *,
    seed: int,
    dt: float,
    time: float,
    collisions: str,
    width: float,
    height: float,
    k: float | None = None,
    softening: float = 0.0,
    boundary: str = "reflecting",
    description: str | None = None,
) -> Scenario:
    """Assemble and validate a preset's scenario (a Coulomb force when ``k`` is given; the
    registered description unless ``description`` is given)."""
    forces = [] if k is None else [{"type": "coulomb", "k": k, "softening": softening}]
    return Scenario.from_dict(
        {
            "name": name,
            "description": _ABOUT[name][1] if description is None else description,
            "seed": seed,
            "box": {"width": width, "height": height, "boundary": boundary},
            "run": {"dt": dt, "time": time, "collisions": collisions},
            "forces": forces,
            "particles": particles,
        }
    )


def _pair(
    position: list[list[float]],
    velocity: list[list[float]],
    mass: float | list[float],
    radius: float,
    charge: float | list[float] = 0.0,
) -> dict[str, Any]:
    """An explicit particle group."""
    return {
        "kind": "explicit",
        "position": position,
        "velocity": velocity,
        "mass": mass,
        "radius": radius,
        "charge": charge,
    }


@_preset("head-on", "3.1.1", "two neutral disks meet head-on at the origin and swap velocities")
def head_on(
    *,
    seed: int = 1,
    dt: float = 0.01,
    time: float = 10.0,
    collisions: Collisions = "exact",
    mass: float = 1.0,
    radius: float = 0.25,
    width: float = 20.0,
    height: float = 20.0,
) -> Scenario:
    """Neutral disks at (-1, 0) and (1, 0) m with velocities (5, 0) and (-5, 0) m/s."""
    particles = [_pair([[-1.0, 0.0], [1.0, 0.0]], [[5.0, 0.0], [-5.0, 0.0]], mass, radius)]
    return _scenario(
        "head-on",
        particles,
        seed=seed,
        dt=dt,
        time=time,
        collisions=collisions,
        width=width,
        height=height,
    )


@_preset("right-angle", "3.1.2", "two neutral disks meet at 90 degrees and leave left and down")
def right_angle(
    *,
    seed: int = 1,
    dt: float = 0.01,
    time: float = 10.0,
    collisions: Collisions = "exact",
    mass: float = 1.0,
    radius: float = 0.25,
    width: float = 20.0,
    height: float = 20.0,
) -> Scenario:
    """Neutral disks at (0, 1) and (1, 0) m with velocities (0, -5) and (-5, 0) m/s."""
    particles = [_pair([[0.0, 1.0], [1.0, 0.0]], [[0.0, -5.0], [-5.0, 0.0]], mass, radius)]
    return _scenario(
        "right-angle",
        particles,
        seed=seed,
        dt=dt,
        time=time,
        collisions=collisions,
        width=width,
        height=height,
    )


@_preset("gas", "3.1.3", "neutral disks (200) at random; speeds relax to Maxwell-Boltzmann")
def gas(
    *,
    n: int = 200,
    speed: float = 10.0,
    seed: int = 1,
    dt: float = 0.01,
    time: float = 10.0,
    collisions: Collisions = "exact",
    mass: float = 1.0,
    radius: float = 0.25,
    width: float = 20.0,
    height: float = 20.0,
    boundary: Boundary = "reflecting",
) -> Scenario:
    """``n`` neutral disks at uniform random non-overlapping positions, velocity components
    uniform in ``[-speed, speed]`` m/s."""
    particles = [{"kind": "random", "n": n, "mass": mass, "radius": radius, "speed": speed}]
    return _scenario(
        "gas",
        particles,
        seed=seed,
        dt=dt,
        time=time,
        collisions=collisions,
        width=width,
        height=height,
        boundary=boundary,
        description=f"{n} neutral disks at random; speeds relax to Maxwell-Boltzmann",
    )


@_preset("charged-like", "3.2.1", "two +1 C charges approach, stop short of contact, turn back")
def charged_like(
    *,
    k: float = 5.0,
    seed: int = 1,
    dt: float = 0.01,
    time: float = 10.0,
    collisions: Collisions = "exact",
    mass: float = 1.0,
    radius: float = 0.25,
    width: float = 20.0,
    height: float = 20.0,
) -> Scenario:
    """+1 C at (-5, 0) m moving (2, 0) m/s and +1 C at (5, 0) m moving (-2, 0) m/s; Coulomb k."""
    particles = [_pair([[-5.0, 0.0], [5.0, 0.0]], [[2.0, 0.0], [-2.0, 0.0]], mass, radius, 1.0)]
    return _scenario(
        "charged-like",
        particles,
        seed=seed,
        dt=dt,
        time=time,
        collisions=collisions,
        width=width,
        height=height,
        k=k,
    )


@_preset("charged-opposite", "3.2.1", "+1 C and -1 C attract and collide, again and again")
def charged_opposite(
    *,
    k: float = 5.0,
    seed: int = 1,
    dt: float = 0.01,
    time: float = 10.0,
    collisions: Collisions = "exact",
    mass: float = 1.0,
    radius: float = 0.25,
    width: float = 20.0,
    height: float = 20.0,
) -> Scenario:
    """+1 C at (-5, 0) m moving (2, 0) m/s and -1 C at (5, 0) m moving (-2, 0) m/s; Coulomb k."""
    return _opposite(
        "charged-opposite",
        k=k,
        softening=0.0,
        seed=seed,
        dt=dt,
        time=time,
        collisions=collisions,
        mass=mass,
        radius=radius,
        width=width,
        height=height,
    )


def _opposite(
    name: str, *, radius: float, mass: float, k: float, softening: float, **run: Any
) -> Scenario:
    """The opposite-charges pair of seed 3.2.1 (and 4.2.1)."""
    particles = [
        _pair([[-5.0, 0.0], [5.0, 0.0]], [[2.0, 0.0], [-2.0, 0.0]], mass, radius, [1.0, -1.0])
    ]
    return _scenario(name, particles, k=k, softening=softening, **run)


@_preset("orbit", "3.2.2", "-1 C and +1 C orbit each other on an ellipse (period about 9.4 s)")
def orbit(
    *,
    k: float = 5.0,
    seed: int = 1,
    dt: float = 0.01,
    time: float = 10.0,
    collisions: Collisions = "exact",
    mass: float = 1.0,
    radius: float = 0.25,
    width: float = 20.0,
    height: float = 20.0,
) -> Scenario:
    """-1 C at (-2, 0) m moving (0, -0.6) m/s and +1 C at (2, 0) m moving (0, 0.6) m/s."""
    particles = [
        _pair([[-2.0, 0.0], [2.0, 0.0]], [[0.0, -0.6], [0.0, 0.6]], mass, radius, [-1.0, 1.0])
    ]
    return _scenario(
        "orbit",
        particles,
        seed=seed,
        dt=dt,
        time=time,
        collisions=collisions,
        width=width,
        height=height,
        k=k,
    )


@_preset("bohr-atom", "3.2.2", "two light -1 C electrons orbit a heavy +10 C nucleus")
def bohr_atom(
    *,
    k: float = 5.0,
    seed: int = 1,
    dt: float = 0.01,
    time: float = 10.0,
    collisions: Collisions = "exact",
    radius: float = 0.25,
    width: float = 20.0,
    height: float = 20.0,
) -> Scenario:
    """+10 C, 100 kg nucleus at rest at the origin; -1 C, 0.1 kg electrons at (3, 0) m moving
    (0, 12.9) m/s and at (-5, 0) m moving (0, -10) m/s."""
    particles = [
        _pair(
            [[0.0, 0.0], [3.0, 0.0], [-5.0, 0.0]],
            [[0.0, 0.0], [0.0, 12.9], [0.0, -10.0]],
            [100.0, 0.1, 0.1],
            radius,
            [10.0, -1.0, -1.0],
        )
    ]
    return _scenario(
        "bohr-atom",
        particles,
        seed=seed,
        dt=dt,
        time=time,
        collisions=collisions,
        width=width,
        height=height,
        k=k,
    )


@_preset("charged-gas", "3.2.3", "disks (200) at random, +1 C and -1 C in equal numbers")
def charged_gas(
    *,
    n: int = 200,
    speed: float = 10.0,
    charge: float = 1.0,
    k: float = 5.0,
    seed: int = 1,
    dt: float = 0.01,
    time: float = 10.0,
    collisions: Collisions = "exact",
    mass: float = 1.0,
    radius: float = 0.25,
    width: float = 20.0,
    height: float = 20.0,
    boundary: Boundary = "reflecting",
) -> Scenario:
    """The gas preset with charges ``+charge`` / ``-charge`` C in equal numbers, in random order,
    and a Coulomb force."""
    particles = [
        {
            "kind": "random",
            "n": n,
            "mass": mass,
            "radius": radius,
            "speed": speed,
            "charge": charge,
            "charges": "balanced",
        }
    ]
    return _scenario(
        "charged-gas",
        particles,
        seed=seed,
        dt=dt,
        time=time,
        collisions=collisions,
        width=width,
        height=height,
        boundary=boundary,
        k=k,
        description=f"{n} disks at random, +{charge:g} C and -{charge:g} C in equal numbers",
    )


@_preset("pool-break", "4.1.1", "a cue ball at 100 m/s breaks a 224-ball rack on a 40 x 20 table")
def pool_break(
    *,
    speed: float = 100.0,
    seed: int = 1,
    dt: float = 0.01,
    time: float = 60.0,
    collisions: Collisions = "exact",
    mass: float = 1.0,
    radius: float = 0.25,
    width: float = 40.0,
    height: float = 20.0,
) -> Scenario:
    """A rhombus rack of 224 balls at rest, apex pointing left at (3, 0) m, columns of
    1, 2, ..., 15, ..., 2 balls, neighbouring centres ``2 r (1 + 0.005)`` apart (a gap of 1% of
    r); a cue ball at (-10, 0) m moving (``speed``, 0) m/s."""
    particles = [
        {
            "kind": "rack",
            "apex": [3.0, 0.0],
            "rows": 15,
            "radius": radius,
            "mass": mass,
            "gap": 0.01,
        },
        _pair([[-10.0, 0.0]], [[speed, 0.0]], mass, radius),
    ]
    return _scenario(
        "pool-break",
        particles,
        seed=seed,
        dt=dt,
        time=time,
        collisions=collisions,
        width=width,
        height=height,
        description=f"a cue ball at {speed:g} m/s breaks a 224-ball rack on a "
        f"{width:g} x {height:g} table",
    )


@_preset(
    "charged-no-collisions",
    "4.2.1",
    "charged-opposite with radius 0 and softening 0.05: they pass through; try smaller dt",
)
def charged_no_collisions(
    *,
    softening: float = 0.05,
    k: float = 5.0,
    seed: int = 1,
    dt: float = 0.01,
    time: float = 10.0,
    collisions: Collisions = "exact",
    mass: float = 1.0,
    radius: float = 0.0,
    width: float = 20.0,
    height: float = 20.0,
) -> Scenario:
    """The charged-opposite pair as point particles (radius 0) with Coulomb softening 0.05 m
    (the seed's epsilon); try dt 0.01, 0.005, 0.001 s."""
    return _opposite(
        "charged-no-collisions",
        k=k,
        softening=softening,
        seed=seed,
        dt=dt,
        time=time,
        collisions=collisions,
        mass=mass,
        radius=radius,
        width=width,
        height=height,
    )


def presets() -> list[str]:
    """Names of the presets, in the seed report's order."""
    return list(PRESETS)


def parameters(name: str) -> dict[str, Any]:
    """The keyword parameters of a preset and their defaults."""
    signature = inspect.signature(_function(name))
    return {key: p.default for key, p in signature.parameters.items()}


def preset(name: str, **overrides: Any) -> Scenario:
    """The scenario of a preset, with keyword overrides.

    Parameters
    ----------
    name : str
        A name from `presets`.
    **overrides
        Parameters of that preset (see `parameters`), e.g. ``n=500, seed=3`` for ``"gas"``.

    Raises
    ------
    InputError
        ``preset`` for an unknown name; the parameter for one the preset does not take; the
        scenario field for a bad value.
    """
    function = _function(name)
    allowed = parameters(name)
    for key in overrides:
        if key not in allowed:
            raise InputError(
                key, f"not a parameter of preset {name!r}; it takes: {', '.join(allowed)}"
            )
    try:
        return function(**overrides)
    except InputError as exc:
        parameter = exc.field.split(".")[-1]
        if parameter in overrides and parameter != exc.field:
            raise InputError(parameter, exc.reason) from exc
        raise


def describe_presets() -> list[dict[str, Any]]:
    """One entry per preset: ``name``, ``section`` (of the seed report), ``description`` and
    ``parameters`` (name -> default), for listings."""
    return [
        {
            "name": name,
            "section": _ABOUT[name][0],
            "description": _ABOUT[name][1],
            "parameters": parameters(name),
        }
        for name in PRESETS
    ]


def _function(name: str) -> PresetFunction:
    try:
        return PRESETS[name]
    except (KeyError, TypeError):
        raise InputError(
            "preset", f"unknown preset {name!r}; choose from {', '.join(PRESETS)}"
        ) from None
