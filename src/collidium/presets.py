"""The seed report's configurations as scenarios: one small builder per preset, registered by name.

Default vessel: a 20 m x 20 m reflecting box centred on the origin (a circle of radius
``vessel_radius`` for the presets that take it); m = 1 kg, r = 0.25 m,
k = 5 N m^2/C^2, dt = 0.01 s, seed 1, run time 10 s (pool-break: 60 s), unless a preset says
otherwise. Every preset takes keyword overrides and gives a `Scenario`::

    preset("gas", n=500, seed=3).build().run(time=5.0)

The settings the presets share (seed, run, vessel, Coulomb force, particle mass and radius) are
declared once in `_COMMON`; each preset names the ones it takes and only builds its particle
groups, from the shared values it needs and its own knobs (``n``, ``speed``, ``charge``...).
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

from collidium.errors import InputError
from collidium.initial import CLOSE_PACKING, lattice_spacing
from collidium.integrators import DEFAULT_TOLERANCE

if TYPE_CHECKING:
    from collidium.scenario import Scenario

PresetFunction = Callable[..., "Scenario"]
Particles = list[dict[str, Any]]
#: Builds a preset's particle groups: positional parameters are shared settings it needs
#: (``mass``, ``radius``...), keyword-only ones (with defaults) are the preset's own knobs. A
#: preset that needs more returns a dict: ``particles``, and any of ``walls`` (the vessel's wall
#: tables by name), ``partitions`` (the vessel's partition tables), ``run`` (run settings),
#: ``forces`` (force tables besides the Coulomb force of a preset taking ``k``) and
#: ``observers`` (observer tables).
Builder = Callable[..., Particles | dict[str, Any]]
AnyBuilder = TypeVar("AnyBuilder", bound=Builder)

#: The shared settings with their usual defaults, in the order presets list them.
_COMMON: dict[str, Any] = {
    "softening": 0.0,
    "k": 5.0,
    "seed": 1,
    "dt": 0.01,
    "time": 10.0,
    "collisions": "exact",
    "integrator": "adaptive",
    "tolerance": DEFAULT_TOLERANCE,
    "mass": 1.0,
    "radius": 0.25,
    "width": 20.0,
    "height": 20.0,
    "boundary": "reflecting",
    # A circular vessel's radius, m: about the area of the 20 m x 20 m box.
    "vessel_radius": 11.3,
}
_NEUTRAL = (
    "seed", "dt", "time", "collisions", "integrator", "tolerance", "mass", "radius", "width",
    "height",
)  # fmt: skip
#: A preset taking ``k`` has a Coulomb force (softened by ``softening``).
_CHARGED = ("k", *_NEUTRAL)


@dataclass(frozen=True)
class _Entry:
    """A registered preset."""

    build: Builder
    section: str
    description: str
    #: The scenario's description, formatted with the parameters (the description if None).
    title: str | None
    #: Parameter name -> default, the preset's own knobs first.
    parameters: dict[str, Any]


#: Preset name -> function returning its `Scenario` (``preset`` with that name).
PRESETS: dict[str, PresetFunction] = {}
_ENTRIES: dict[str, _Entry] = {}


def _preset(
    name: str,
    section: str,
    description: str,
    *,
    common: tuple[str, ...] = _NEUTRAL,
    title: str | None = None,
    **defaults: Any,
) -> Callable[[AnyBuilder], AnyBuilder]:
    """Register a preset under ``name``: it takes the shared settings ``common`` (with
    ``defaults`` replacing the usual ones) and the keyword-only parameters of its builder."""
    if not set(defaults) <= set(common) <= set(_COMMON):
        raise ValueError(f"preset {name!r}: unknown shared setting or default")

    def register(build: AnyBuilder) -> AnyBuilder:
        signature = inspect.signature(build).parameters.values()
        knobs = {p.name: p.default for p in signature if p.kind is p.KEYWORD_ONLY}
        shared = {key: defaults.get(key, value) for key, value in _COMMON.items() if key in common}
        _ENTRIES[name] = _Entry(build, section, description, title, knobs | shared)
        PRESETS[name] = lambda **overrides: preset(name, **overrides)
        return build

    return register


def _charged(name: str, section: str, description: str) -> Callable[[AnyBuilder], AnyBuilder]:
    """Register a preset of charges with a Coulomb force and the usual shared settings."""
    return _preset(name, section, description, common=_CHARGED)


def _scenario(name: str, values: dict[str, Any]) -> Scenario:
    """Assemble and validate a preset's scenario from all its parameter values."""
    from collidium.scenario import Scenario  # on first use (`collidium.loading`)

    entry = _ENTRIES[name]
    arguments = inspect.signature(entry.build).parameters
    built = entry.build(**{key: values[key] for key in arguments})
    parts: dict[str, Any] = built if isinstance(built, dict) else {"particles": built}
    title = entry.description if entry.title is None else entry.title.format(**values)
    forces = []
    if "k" in entry.parameters:
        forces.append({"type": "coulomb", "k": values["k"], "softening": values["softening"]})
    forces.extend(parts.get("forces", []))
    return Scenario.from_dict(
        {
            "name": name,
            "description": title,
            "seed": values["seed"],
            "vessel": _vessel(entry, values)
            | parts.get("vessel", {})
            | {key: parts[key] for key in ("walls", "partitions") if key in parts},
            "run": {
                key: values[key] for key in ("dt", "time", "collisions", "integrator", "tolerance")
            }
            | parts.get("run", {}),
            "forces": forces,
            "particles": parts["particles"],
            "observers": parts.get("observers", []),
        }
    )


def _vessel(entry: _Entry, values: dict[str, Any]) -> dict[str, Any]:
    """A preset's vessel table: a circle for the presets taking ``vessel_radius``, else a box."""
    if "vessel_radius" in entry.parameters:
        return {"shape": "circle", "radius": values["vessel_radius"]}
    return {key: values[key] for key in ("width", "height", "boundary")}


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
def head_on(mass: float, radius: float) -> Particles:
    """Neutral disks at (-1, 0) and (1, 0) m with velocities (5, 0) and (-5, 0) m/s."""
    return [_pair([[-1.0, 0.0], [1.0, 0.0]], [[5.0, 0.0], [-5.0, 0.0]], mass, radius)]


@_preset("right-angle", "3.1.2", "two neutral disks meet at 90 degrees and leave left and down")
def right_angle(mass: float, radius: float) -> Particles:
    """Neutral disks at (0, 1) and (1, 0) m with velocities (0, -5) and (-5, 0) m/s."""
    return [_pair([[0.0, 1.0], [1.0, 0.0]], [[0.0, -5.0], [-5.0, 0.0]], mass, radius)]


@_preset(
    "gas",
    "3.1.3",
    "neutral disks (200) at random; speeds relax to Maxwell-Boltzmann",
    common=(*_NEUTRAL, "boundary"),
    title="{n} neutral disks at random; speeds relax to Maxwell-Boltzmann",
)
def gas(mass: float, radius: float, *, n: int = 200, speed: float = 10.0) -> Particles:
    """``n`` neutral disks at uniform random non-overlapping positions, velocity components
    uniform in ``[-speed, speed]`` m/s."""
    return [{"kind": "random", "n": n, "mass": mass, "radius": radius, "speed": speed}]


@_charged("charged-like", "3.2.1", "two +1 C charges approach, stop short of contact, turn back")
def charged_like(mass: float, radius: float) -> Particles:
    """+1 C at (-5, 0) m moving (2, 0) m/s and +1 C at (5, 0) m moving (-2, 0) m/s; Coulomb k."""
    return [_pair([[-5.0, 0.0], [5.0, 0.0]], [[2.0, 0.0], [-2.0, 0.0]], mass, radius, 1.0)]


@_charged("charged-opposite", "3.2.1", "+1 C and -1 C attract and collide, again and again")
def charged_opposite(mass: float, radius: float) -> Particles:
    """+1 C at (-5, 0) m moving (2, 0) m/s and -1 C at (5, 0) m moving (-2, 0) m/s; Coulomb k."""
    return [_pair([[-5.0, 0.0], [5.0, 0.0]], [[2.0, 0.0], [-2.0, 0.0]], mass, radius, [1.0, -1.0])]


@_charged("orbit", "3.2.2", "-1 C and +1 C orbit each other on an ellipse (period about 9.4 s)")
def orbit(mass: float, radius: float) -> Particles:
    """-1 C at (-2, 0) m moving (0, -0.6) m/s and +1 C at (2, 0) m moving (0, 0.6) m/s."""
    return [_pair([[-2.0, 0.0], [2.0, 0.0]], [[0.0, -0.6], [0.0, 0.6]], mass, radius, [-1.0, 1.0])]


@_preset(
    "bohr-atom",
    "3.2.2",
    "two light -1 C electrons orbit a heavy +10 C nucleus",
    common=tuple(key for key in _CHARGED if key != "mass"),
)
def bohr_atom(radius: float) -> Particles:
    """+10 C, 100 kg nucleus at rest at the origin; -1 C, 0.1 kg electrons at (3, 0) m moving
    (0, 12.9) m/s and at (-5, 0) m moving (0, -10) m/s."""
    return [
        _pair(
            [[0.0, 0.0], [3.0, 0.0], [-5.0, 0.0]],
            [[0.0, 0.0], [0.0, 12.9], [0.0, -10.0]],
            [100.0, 0.1, 0.1],
            radius,
            [10.0, -1.0, -1.0],
        )
    ]


@_preset(
    "charged-gas",
    "3.2.3",
    "disks (200) at random, +1 C and -1 C in equal numbers",
    common=(*_CHARGED, "boundary"),
    title="{n} disks at random, +{charge:g} C and -{charge:g} C in equal numbers",
)
def charged_gas(
    mass: float, radius: float, *, n: int = 200, speed: float = 10.0, charge: float = 1.0
) -> Particles:
    """The gas preset with charges ``+charge`` / ``-charge`` C in equal numbers, in random order,
    and a Coulomb force."""
    group = gas(mass, radius, n=n, speed=speed)[0]
    return [group | {"charge": charge, "charges": "balanced"}]


@_preset(
    "pool-break",
    "4.1.1",
    "a cue ball at 100 m/s breaks a 224-ball rack on a 40 x 20 table",
    title="a cue ball at {speed:g} m/s breaks a 224-ball rack on a {width:g} x {height:g} table",
    time=60.0,
    width=40.0,
)
def pool_break(mass: float, radius: float, *, speed: float = 100.0) -> Particles:
    """A rhombus rack of 224 balls at rest, apex pointing left at (3, 0) m, columns of
    1, 2, ..., 15, ..., 2 balls, neighbouring centres ``2 r (1 + 0.005)`` apart (a gap of 1% of
    r); a cue ball at (-10, 0) m moving (``speed``, 0) m/s."""
    rack = {
        "kind": "rack",
        "apex": [3.0, 0.0],
        "rows": 15,
        "radius": radius,
        "mass": mass,
        "gap": 0.01,
    }
    return [rack, _pair([[-10.0, 0.0]], [[speed, 0.0]], mass, radius)]


@_preset(
    "charged-no-collisions",
    "4.2.1",
    "charged-opposite with radius 0 and softening 0.05: they pass through; try smaller dt",
    common=("softening", *_CHARGED),
    softening=0.05,
    radius=0.0,
)
def charged_no_collisions(mass: float, radius: float) -> Particles:
    """The charged-opposite pair as point particles (radius 0) with Coulomb softening 0.05 m
    (the seed's epsilon); try dt 0.01, 0.005, 0.001 s."""
    return charged_opposite(mass, radius)


@_preset(
    "circle-gas",
    "5",
    "neutral disks (200) at random in a circular vessel; energy and angular momentum constant",
    common=(*(key for key in _NEUTRAL if key not in ("width", "height")), "vessel_radius"),
    title="{n} neutral disks at random in a circle of radius {vessel_radius:g} m",
)
def circle_gas(mass: float, radius: float, *, n: int = 200, speed: float = 10.0) -> Particles:
    """The gas preset in a circle of radius ``vessel_radius`` (11.3 m): the rim conserves the
    angular momentum about the centre as well as the energy (the seed's future work: other
    shapes of vessel)."""
    return gas(mass, radius, n=n, speed=speed)


@_preset(
    "hard-disks",
    "5",
    "a hard-disk fluid at a packing fraction in a periodic box: its pressure, Z(eta)",
    common=tuple(key for key in _NEUTRAL if key not in ("width", "height")),
    title="{columns} x {rows} hard disks at packing {packing:g} in a periodic box",
    radius=0.5,
    time=50.0,
)
def hard_disks(
    mass: float,
    radius: float,
    *,
    packing: float = 0.3,
    columns: int = 20,
    rows: int = 20,
    speed: float = 1.0,
) -> dict[str, Any]:
    """``columns x rows`` disks start on a hexagonal lattice at ``packing`` that fills a periodic
    box exactly (``rows`` even), velocity components uniform in ``[-speed, speed]`` m/s (kT =
    m speed^2 / 3); the lattice melts below a packing of about 0.70. The run's virial pressure
    gives the equation of state ``Z = P A / (N kT)`` (``compressibility`` in the summary), to set
    against Henderson's formula (`collidium.theory.hard_disk_compressibility`); the seed's future
    work asks for exactly this curve."""
    if rows % 2:
        raise InputError(
            "rows", f"must be even, so that the lattice fills the periodic box; got {rows}"
        )
    if not 0.0 < packing <= CLOSE_PACKING:
        raise InputError("packing", f"must be in (0, {CLOSE_PACKING:.4f}], got {packing!r}")
    spacing = lattice_spacing(radius, packing)
    width, height = columns * spacing, rows * spacing * math.sqrt(3.0) / 2.0
    lattice = {"kind": "lattice", "columns": columns, "rows": rows, "packing": packing,
               "radius": radius, "mass": mass, "speed": speed}  # fmt: skip
    return {
        "vessel": {"width": width, "height": height, "boundary": "periodic"},
        "particles": [lattice],
    }


#: Largest ``digits`` of pi-blocks: double precision gives every count up to 8 (314159265
#: collisions, 14 s); beyond, round-off could change the count.
PI_DIGITS = 8


@_preset(
    "pi-blocks",
    "5",
    "a block slides into a lighter one before a wall: the collisions count the digits of pi",
    title="blocks of mass ratio 100^{digits}: total collisions (pair + wall) = the first "
    "{digits} + 1 digits of pi",
)
def pi_blocks(mass: float, radius: float, *, digits: int = 5, speed: float = 1.0) -> Particles:
    """Two disks on the x axis: a block of ``mass`` at rest at (-9, 0) m, 0.75 m from the left
    wall, and one of ``mass * 100^digits`` at (-7, 0) m moving (-``speed``, 0) m/s. Counting the
    collisions between them and of the light one with the wall gives 3, 31, 314, 3141, ...
    (Galperin's billiard), ``digits`` from 0 to `PI_DIGITS`."""
    if isinstance(digits, bool) or not isinstance(digits, int) or not 0 <= digits <= PI_DIGITS:
        raise InputError("digits", f"must be a whole number from 0 to {PI_DIGITS}, got {digits!r}")
    heavy = mass * 100.0**digits
    return [_pair([[-9.0, 0.0], [-7.0, 0.0]], [[0.0, 0.0], [-speed, 0.0]], [mass, heavy], radius)]


@_preset(
    "brownian",
    "5",
    "one heavy large disk among 2000 small ones: a random walk, traced; its MSD slope gives D",
    common=(*_NEUTRAL, "boundary"),
    title="a disk of {heavy_mass:g} kg and radius {heavy_radius:g} m among {n} small ones",
    radius=0.1,
    width=40.0,
    height=40.0,
    boundary="periodic",
    time=300.0,
)
def brownian(
    mass: float, radius: float, *, n: int = 2000, speed: float = 10.0, heavy_mass: float = 50.0,
    heavy_radius: float = 1.0,
) -> dict[str, Any]:  # fmt: skip
    """A disk of ``heavy_mass`` kg and ``heavy_radius`` m at rest at the origin (particle 0)
    among ``n`` small disks at random (velocity components uniform in ``[-speed, speed]`` m/s)
    in a periodic 40 m x 40 m box; a tracer follows it. Kicked by the small ones it takes their
    temperature and wanders: its mean-square displacement grows as ``4 D t``. One walk gives D
    to within a factor of about two in the default 300 s; longer runs or several seeds narrow
    it."""
    heavy = _pair([[0.0, 0.0]], [[0.0, 0.0]], heavy_mass, heavy_radius)
    return {
        "particles": [heavy, *gas(mass, radius, n=n, speed=speed)],
        "observers": [{"kind": "tracer", "particles": [0], "every": 10}],
    }


@_preset(
    "heat-flow",
    "5",
    "a gas between a hot wall (left) and a cold one (right): a temperature profile, heat flux",
    common=(*_NEUTRAL, "boundary"),
    title="{n} disks between walls at kT = {hot:g} J (left) and {cold:g} J (right)",
    width=40.0,
    height=10.0,
    time=60.0,
)
def heat_flow(
    mass: float, radius: float, *, n: int = 300, speed: float = 7.0, hot: float = 30.0,
    cold: float = 5.0,
) -> dict[str, Any]:  # fmt: skip
    """``n`` disks at random (velocity components uniform in ``[-speed, speed]`` m/s) in a
    40 m x 10 m box whose left wall is thermal at kT = ``hot`` J and right wall at ``cold`` J
    (the top and bottom are mirrors). Heat flows from left to right (``wall_heat``); a
    temperature profile in 10 slices along x is measured after 20 s."""
    return {
        "particles": gas(mass, radius, n=n, speed=speed),
        "walls": {
            "left": {"response": "thermal", "temperature": hot},
            "right": {"response": "thermal", "temperature": cold},
        },
        "observers": [{"kind": "profile", "bins": 10, "axis": "x", "after": 20.0, "every": 10}],
    }


@_preset(
    "granular",
    "5",
    "inelastic disks (e = 0.9) in a periodic box: the gas cools as Haff's law",
    common=(*_NEUTRAL, "boundary"),
    title="{n} inelastic disks (e = {restitution:g}) cooling: T(t) = T0 / (1 + t / tau)^2",
    width=60.0,
    height=60.0,
    boundary="periodic",
    time=30.0,
)
def granular(
    mass: float, radius: float, *, n: int = 2000, speed: float = 1.7, restitution: float = 0.9
) -> dict[str, Any]:
    """``n`` disks at random (velocity components uniform in ``[-speed, speed]`` m/s, so
    kT0 = m speed^2 / 3) in a periodic 60 m x 60 m box, colliding with normal restitution
    ``restitution``. The homogeneous gas cools as Haff's law (`collidium.theory.haff_time`,
    about 18 s at the defaults); later, much longer, it forms clusters. The energy the collisions
    take is ``collision_heat``."""
    return {"particles": gas(mass, radius, n=n, speed=speed), "run": {"restitution": restitution}}


@_preset(
    "piston",
    "5",
    "a gas under a free piston with a weight: it settles where the gas pressure is F/L; "
    "or a driven slow compression, P A^2 constant",
    title="{n} disks under a piston of {piston_mass:g} kg pushed in by {force:g} N "
    "(driven at {compress:g} m/s when not 0)",
    width=20.0,
    height=40.0,
    time=60.0,
)
def piston(
    mass: float, radius: float, *, n: int = 200, speed: float = 5.0, piston_mass: float = 20.0,
    force: float = 80.0, start: float = 0.0, compress: float = 0.0,
) -> dict[str, Any]:  # fmt: skip
    """``n`` disks at random (velocity components uniform in ``[-speed, speed]`` m/s) below the
    top wall of a 20 m x 40 m box, a piston whose face starts at y = ``start`` m. Free (the
    default), it has a mass of ``piston_mass`` kg and a weight ``force`` N pushes it down: it
    oscillates, the gas and the piston share their energy, and it settles about the height where
    the gas pressure on it equals ``force`` / 20 m (the hard-disk equation of state,
    `collidium.theory.hard_disk_compressibility`). With ``compress`` > 0 it is driven down at
    that speed (m/s) until the chamber is half as tall: slowly (far below the thermal speed),
    the compression is adiabatic and, in 2D, ``P A^2`` stays constant (gamma = 2); run it for
    ``time`` = (start + 20) / (2 compress) s to the end."""
    if compress:
        bottom = -20.0
        stop = bottom + 0.5 * (start - bottom)
        top = {"response": "piston", "position": start, "velocity": -compress, "driven": True,
               "stop": stop}  # fmt: skip
    else:
        top = {"response": "piston", "position": start, "mass": piston_mass, "force": force}
    return {"particles": gas(mass, radius, n=n, speed=speed), "walls": {"top": top}}


@_preset(
    "effusion",
    "5",
    "two masses leak through a hole in a partition: the lighter escapes faster, "
    "by sqrt(m2/m1) (Graham)",
    title="{n} disks of {mass:g} kg and {n} of {heavy_mass:g} kg leak through a {gap:g} m hole",
    radius=0.02,
    width=40.0,
    height=20.0,
    time=200.0,
)
def effusion(
    mass: float, radius: float, width: float, height: float, *, n: int = 500,
    heavy_mass: float = 4.0, speed: float = 5.0, gap: float = 2.0,
) -> dict[str, Any]:  # fmt: skip
    """A box cut in two by a partition across its middle (x = 0) with a hole of ``gap`` m;
    ``n`` disks of ``mass`` and ``n`` of ``heavy_mass`` at random in the left chamber, at one
    temperature (velocity components uniform in ``[-speed, speed]`` m/s for the light ones,
    scaled by ``sqrt(mass / heavy_mass)`` for the heavy ones). Both leak into the right chamber,
    the lighter faster: the `collidium.observers.Effusion` observer counts each species'
    crossings, whose rates per disk stand in the ratio ``sqrt(heavy_mass / mass)``. The mean
    free path (about 3.5 m in the full chamber at the defaults, 7 m once the disks are spread
    over both) is longer than the hole: the disks effuse rather than flow."""
    half_width, half_height = 0.5 * width, 0.5 * height
    left = [[-half_width, -half_height], [0.0, half_height]]
    light, heavy = (
        {"kind": "random", "n": n, "mass": m, "radius": radius, "region": left,
         "speed": speed * (mass / m) ** 0.5}
        for m in (mass, heavy_mass)
    )  # fmt: skip
    divider = {"name": "divider", "start": [0.0, -half_height], "end": [0.0, half_height],
               "gap": gap}  # fmt: skip
    return {
        "particles": [light, heavy],
        "partitions": [divider],
        "observers": [{"kind": "effusion", "partition": "divider"}],
    }


@_preset(
    "atmosphere",
    "5",
    "a gas under uniform gravity in a tall box: the density falls as exp(-m g y / kT)",
    common=(*_NEUTRAL, "boundary"),
    title="{n} disks under gravity g = {g:g} m/s^2: density as exp(-m g y / kT)",
    radius=0.1,
    width=40.0,
    height=100.0,
    time=120.0,
)
def atmosphere(
    mass: float, radius: float, *, n: int = 2000, speed: float = 10.0, g: float = 1.0
) -> dict[str, Any]:
    """``n`` disks at random (velocity components uniform in ``[-speed, speed]`` m/s, kT about
    ``m speed^2 / 3``) in a 40 m x 100 m box under uniform gravity ``g`` downwards. Collisions
    share the energy between heights; in equilibrium the temperature is the same at every height
    and, where the gas is dilute (the upper part), the density falls as the barometric law
    ``exp(-m g y / kT)``, a scale height ``kT / (m g)`` of about 47 m at the defaults (the fall
    heats the gas from kT = 33 J; `collidium.theory.barometric_density`). The disks are small
    (radius 0.1 m, packing fraction below 0.03) so that the gas is nearly ideal: with radius
    0.25 m the hard-disk pressure ``n kT (1 + 2 eta + ...)`` stretches the profile by a tenth
    or more. The profile of density and temperature in 20 slices is measured from 40 s on."""
    return {
        "particles": gas(mass, radius, n=n, speed=speed),
        "forces": [{"type": "gravity", "g": [0.0, -g]}],
        "observers": [{"kind": "profile", "bins": 20, "axis": "y", "after": 40.0, "every": 10}],
    }


@_preset(
    "projectile",
    "5",
    "a charge moving along a negatively charged bottom plate: a parabola (seed's future work)",
    title="a +{charge:g} C charge at {speed:g} m/s over a plate pulling with E = {field:g} N/C",
    time=5.0,
)
def projectile(
    mass: float, radius: float, *, speed: float = 4.0, field: float = 2.0, charge: float = 1.0
) -> dict[str, Any]:
    """A charge ``charge`` (C) at (-8, 0) m moving at ``speed`` m/s along the x axis, above a
    negatively charged bottom plate: a uniform field ``E = (0, -field)`` N/C. It falls on a
    parabola and meets the floor (y = -10 m + radius) after ``t = sqrt(2 h m / (q E))``,
    ``range = speed t`` further on (`collidium.theory.projectile_range`): 12.5 m at the
    defaults; then it bounces."""
    return {
        "particles": [_pair([[-8.0, 0.0]], [[speed, 0.0]], mass, radius, charge)],
        "forces": [{"type": "uniform_field", "E": [0.0, -field]}],
    }


@_preset(
    "spectrometer",
    "5",
    "ions of three masses enter a magnetic field and land apart: radius m v / (q B)",
    title="ions of {mass:g} to 3 x {mass:g} kg at {speed:g} m/s into B = {field:g} T",
    width=24.0,
    height=14.0,
    time=14.0,
)
def spectrometer(
    mass: float, radius: float, *, speed: float = 2.0, field: float = 1.0, charge: float = 1.0
) -> dict[str, Any]:
    """A mass spectrometer: three ions of charge ``charge`` (C) and masses ``mass``, 2 ``mass``
    and 3 ``mass`` leave a slit at x = -10 m upwards at ``speed`` (m/s), one behind the other,
    into a magnetic field ``field`` (T) that fills the box above y = -3 m. Each turns on a half
    circle of radius ``m v / (q B)`` (`collidium.theory.cyclotron_radius`) and comes down at
    x = -10 + 2 r: 2 m, 4 m and 6 m apart at the defaults, where they land on the floor."""
    masses = [3 * mass, 2 * mass, mass]  # the lightest nearest the field, first in
    start = [[-10.0, y] for y in (-6.5, -5.5, -4.5)]
    ions = _pair(start, [[0.0, speed]] * 3, masses, radius, charge)
    magnet = {"type": "magnetic_field", "B": field, "region": [[-12.0, -3.0], [12.0, 7.0]]}
    return {"particles": [ions], "forces": [magnet]}


@_preset(
    "galaxy",
    "5",
    "a cluster of disks held together by Newton's gravity settles to virial equilibrium",
    common=(*(key for key in _NEUTRAL if key not in ("width", "height")), "vessel_radius"),
    title="{n} disks under their own gravity (G = {G:g}): virial ratio 2 KE / |U| towards 1",
    radius=0.02,
    vessel_radius=20.0,
    time=40.0,
    integrator="fixed",
)
def galaxy(
    mass: float,
    radius: float,
    *,
    n: int = 5000,
    G: float = 0.01,
    speed: float = 1.25,
    softening: float = 0.1,
) -> dict[str, Any]:
    """``n`` disks at random in a circle of radius 20 m, velocity components uniform in
    ``[-speed, speed]``, attracting each other by Newton's law (summed by tree, softened by
    ``softening``) and colliding. The start is cold, 2 KE / |U| about 0.5 at the defaults
    (``|U| = 8 G M^2 / (3 pi R)`` for a uniform disk): the cluster falls in within the free-fall
    time ``sqrt(R^3 / (G M))``, 13 s, bounces, throws off a tenth of its disks (the rim sends
    them back) and settles in a few free-fall times: the bound cluster's virial ratio
    ``2 KE / |W|`` (`collidium.observers.VirialRatio`, measured from 25 s on) comes to about 1,
    the virial theorem for an inverse-distance force.

    The step is fixed (``integrator = "fixed"``), holding the energy to 1e-3 over the 40 s: its
    error comes from the collisions under forces (4e-5 with ``collisions = "off"``), each taken
    between kicks. After the collapse the dense core has 1e4 collisions a second, and the
    adaptive integrator, which evaluates the tree again at each of them, would take about 40
    wall seconds per simulated second (``--set run.integrator=adaptive``: 1e-7 over the first
    3 s)."""
    return {
        "particles": gas(mass, radius, n=n, speed=speed),
        "forces": [{"type": "newton", "G": G, "softening": softening, "method": "tree"}],
        "observers": [
            {"kind": "energy", "interval": 1.0},
            {"kind": "virial", "interval": 1.0, "after": 25.0},
        ],
    }


@_preset(
    "drag",
    "5",
    "disks of three masses fall through a fluid and reach terminal velocities m g / gamma",
    title="disks of {mass:g} to 3 x {mass:g} kg falling with drag gamma = {gamma:g} kg/s",
    width=12.0,
    height=40.0,
    time=10.0,
)
def drag(mass: float, radius: float, *, g: float = 1.0, gamma: float = 1.0) -> dict[str, Any]:
    """Three disks of masses ``mass``, 2 ``mass`` and 3 ``mass`` dropped from rest at y = 15 m
    under gravity ``g`` (m/s^2) with linear drag ``gamma`` (kg/s): each speeds up with the time
    constant ``m / gamma`` to its terminal velocity ``m g / gamma``
    (`collidium.theory.terminal_velocity`), 1, 2 and 3 m/s at the defaults."""
    disks = _pair([[-3.0, 15.0], [0.0, 15.0], [3.0, 15.0]], [[0.0, 0.0]] * 3,
                  [mass, 2 * mass, 3 * mass], radius)  # fmt: skip
    forces = [{"type": "gravity", "g": [0.0, -g]}, {"type": "linear_drag", "gamma": gamma}]
    return {"particles": [disks], "forces": forces}


def presets() -> list[str]:
    """Names of the presets, in the seed report's order."""
    return list(PRESETS)


def parameters(name: str) -> dict[str, Any]:
    """The keyword parameters of a preset and their defaults."""
    return dict(_entry(name).parameters)


def preset(name: str, /, **overrides: Any) -> Scenario:
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
    allowed = _entry(name).parameters
    for key, value in overrides.items():
        if key not in allowed:
            raise InputError(
                key, f"not a parameter of preset {name!r}; it takes: {', '.join(allowed)}"
            )
        if isinstance(allowed[key], float) and (
            isinstance(value, bool) or not isinstance(value, int | float)
        ):  # the scenario checks values, but a preset's title formats them first
            raise InputError(key, f"must be a number, got {value!r}")
    try:
        return _scenario(name, _COMMON | allowed | overrides)
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
            "section": entry.section,
            "description": entry.description,
            "parameters": parameters(name),
        }
        for name, entry in _ENTRIES.items()
    ]


def _entry(name: str) -> _Entry:
    try:
        return _ENTRIES[name]
    except (KeyError, TypeError):
        raise InputError(
            "preset", f"unknown preset {name!r}; choose from {', '.join(PRESETS)}"
        ) from None
