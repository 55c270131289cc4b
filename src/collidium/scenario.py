"""Scenario: the pydantic schema of a simulation set-up, read from and written to TOML.

A scenario file::

    name = "gas"
    description = "200 neutral disks"
    seed = 1                      # seeds every random generator in the file

    [vessel]
    shape = "box"                 # "box" | "circle" | "polygon"
    width = 20.0                  # m (box)
    height = 20.0                 # m (box)
    boundary = "reflecting"       # or "periodic" (box)
    # radius = 10.0               # m (circle)
    # vertices = [[0, 0], [20, 0], [20, 8], [8, 8], [8, 20], [0, 20]]   # m (polygon: an L)

    [[vessel.partitions]]         # a straight wall inside, any number of them
    name = "divider"
    start = [0.0, -10.0]          # m
    end = [0.0, 10.0]             # m
    gap = 1.0                     # m, a hole (0: none), centred at gap_at
    gap_at = 0.5                  # fraction of the partition's length

    [vessel.walls.left]           # a wall that is not a mirror, by name
    response = "thermal"          # "specular" | "inelastic" (restitution = e) | "thermal" |
    temperature = 2.0             # kT of the wall, J                        "piston" (a box's)

    # [vessel.walls.top]          # a box wall that moves (exact collisions, no forces)
    # response = "piston"
    # position = 5.0              # m, where its face starts along its axis
    # mass = 10.0                 # kg
    # force = 20.0                # N, pushing it in (a weight); or driven = true, velocity = -0.1

    [run]
    dt = 0.01                     # s, the reporting interval
    time = 10.0                   # s, default duration of `collidium run`
    collisions = "exact"          # "exact" | "step" | "off"
    integrator = "adaptive"       # "adaptive" (substeps as the forces need) | "fixed" (seed's)
    tolerance = 0.003             # the adaptive integrator's accuracy (energy error ~ its square)
    restitution = 1.0             # of the pair collisions, in (0, 1]: below 1, a granular gas

    [[forces]]
    type = "coulomb"
    k = 5.0                       # N m^2 / C^2
    softening = 0.0               # m

    [[particles]]                 # groups, concatenated in order
    kind = "random"               # "explicit" | "random" | "rack" | "lattice"
    n = 200
    speed = 10.0                  # velocity components uniform in [-speed, speed], m/s

    [[observers]]                 # measurements and writers attached to the simulation
    kind = "speeds"               # "energy" | "speeds" | "thermo" | "profile" | "collisions" |
    interval = 0.5                # "tracer" | "trajectory"; every `every` steps or `interval` s,
    after = 5.0                   # from time `after` on

`Scenario.build` turns it into a `Simulation`; the random groups draw, in group order, from one
``numpy.random.default_rng(seed)``, so a scenario always builds the same state bit for bit. Every
validation problem becomes one `InputError` ``field.path: reason``.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import os
import stat
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal, Union, get_origin

import numpy as np
import tomli_w
from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    PlainValidator,
    Tag,
    ValidationError,
    ValidationInfo,
    create_model,
    field_validator,
    model_validator,
)

from collidium.errors import InputError
from collidium.forces import FORCES, Force, parameters
from collidium.forces.base import parameter_path
from collidium.initial import (
    CLOSE_PACKING,
    balanced_charges,
    hexagonal_block,
    random_positions,
    rhombus_rack,
    uniform_velocities,
)
from collidium.integrators import DEFAULT_TOLERANCE
from collidium.io.trajectory import GSDWriter
from collidium.observers import (
    After,
    CollisionRate,
    Effusion,
    EnergySeries,
    Every,
    Interval,
    Observer,
    SpeedHistogram,
    TemperatureProfile,
    Thermo,
    Tracer,
    Trigger,
    VirialRatio,
)
from collidium.simulation import Simulation, outside_detail, overlap_detail
from collidium.state import SPEED_OF_LIGHT, FloatArray, Particles, uniform_or_each
from collidium.vessels import (
    VESSELS,
    Box,
    Circle,
    Inelastic,
    Partition,
    Piston,
    Polygon,
    Specular,
    Thermal,
    Vessel,
    WallResponse,
)

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
#: Fastest velocity component a group may be given, m/s: the fastest disk then moves at up to
#: sqrt(2) times it, still below the speed of light (the mechanics is Newtonian).
FASTEST_COMPONENT = SPEED_OF_LIGHT / math.sqrt(2.0)


def _below_light(speed: float) -> float:
    if speed >= FASTEST_COMPONENT:
        raise ValueError(
            f"must be below {FASTEST_COMPONENT:.4g} m/s (velocity components up to it make speeds "
            f"up to sqrt(2) times it, below the speed of light), got {speed!r}"
        )
    return speed


#: A group's speed scale in m/s: its velocity components are at most this.
Speed = Annotated[NonNegative, AfterValidator(_below_light)]
Vector = Annotated[list[Finite], Field(min_length=2, max_length=2)]

#: Largest particle count of one random group (keeps a typo from exhausting memory).
MAX_GROUP_SIZE = 100_000_000


def _number(value: object, what: str) -> float:
    """A finite float from an int or float (bools and strings refused)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{what} must be a number, got {value!r}")
    number = float(value)
    if not math.isfinite(number):
        raise ValueError(f"{what} must be a finite number, got {value!r}")
    return number


def _per_particle(lower: float | None, strict: bool) -> Callable[[object], float | list[float]]:
    """Validator of a scalar or list of numbers, each finite and above ``lower`` (when given)."""
    sign = ">" if strict else ">="

    def check(number: float, what: str) -> float:
        if lower is not None and (number <= lower if strict else number < lower):
            raise ValueError(f"{what} must be {sign} {lower:g}, got {number!r}")
        return number

    def validate(value: object) -> float | list[float]:
        if isinstance(value, list | tuple):
            return [check(_number(v, f"element {i}"), f"element {i}") for i, v in enumerate(value)]
        return check(_number(value, "value"), "value")

    return validate


PositivePerParticle = Annotated[float | list[float], PlainValidator(_per_particle(0.0, True))]
NonNegativePerParticle = Annotated[float | list[float], PlainValidator(_per_particle(0.0, False))]
FinitePerParticle = Annotated[float | list[float], PlainValidator(_per_particle(None, False))]


class _Model(BaseModel):
    """Base of every schema model: unknown fields are errors, no silent type coercion."""

    model_config = ConfigDict(extra="forbid", strict=True)


class SpecularSpec(_Model):
    """A mirror wall (the default)."""

    response: Literal["specular"]

    def build(self) -> WallResponse:
        """The `Specular` response."""
        return Specular()


class InelasticSpec(_Model):
    """A wall that returns ``restitution`` (in (0, 1]) of the normal velocity."""

    response: Literal["inelastic"]
    restitution: Annotated[float, Field(gt=0.0, le=1.0)]

    def build(self) -> WallResponse:
        """The `Inelastic` response."""
        return Inelastic(self.restitution)


class ThermalSpec(_Model):
    """A wall at temperature kT = ``temperature`` J that re-emits disks thermally."""

    response: Literal["thermal"]
    temperature: Positive

    def build(self) -> WallResponse:
        """The `Thermal` response."""
        return Thermal(self.temperature)


class PistonSpec(_Model):
    """A box wall that moves along its axis (`collidium.vessels.walls.Piston`): its face starts
    at ``position`` (m, along its axis); free, with a ``mass`` (kg) and an inward ``force`` (N),
    or ``driven`` at ``velocity`` (m/s) until ``stop`` (m)."""

    response: Literal["piston"]
    position: float
    mass: Positive = 1.0
    force: NonNegative = 0.0
    velocity: float = 0.0
    driven: bool = False
    stop: float | None = None
    restitution: Annotated[float, Field(gt=0.0, le=1.0)] = 1.0

    def build(self) -> WallResponse:
        """The `Piston` response."""
        return Piston(self.position, self.mass, self.force, self.velocity, self.driven,
                      self.stop, self.restitution)  # fmt: skip


WallSpec = Annotated[
    SpecularSpec | InelasticSpec | ThermalSpec | PistonSpec, Field(discriminator="response")
]


class PartitionSpec(_Model):
    """A straight wall inside the vessel, with an optional hole (`collidium.vessels.Partition`)."""

    name: str
    start: Vector
    end: Vector
    gap: NonNegative = 0.0
    gap_at: Annotated[float, Field(ge=0, le=1)] = 0.5

    def build(self) -> Partition:
        """The `Partition` this describes."""
        return Partition(self.name, (self.start[0], self.start[1]), (self.end[0], self.end[1]),
                         self.gap, self.gap_at)  # fmt: skip


class _VesselSpec(_Model):
    """What every vessel table has: the responses of walls that are not mirrors, by name, and
    the partitions."""

    walls: dict[str, WallSpec] = Field(default_factory=dict)
    partitions: list[PartitionSpec] = Field(default_factory=list)

    def _walls(self) -> dict[str, WallResponse]:
        return {name: spec.build() for name, spec in self.walls.items()}

    def _partitions(self) -> list[Partition]:
        return [spec.build() for spec in self.partitions]


class BoxSpec(_VesselSpec):
    """A rectangular vessel centred on the origin, sides in m (`collidium.vessels.Box`)."""

    shape: Literal["box"] = "box"
    width: Positive = 20.0
    height: Positive = 20.0
    boundary: Literal["reflecting", "periodic"] = "reflecting"

    def build(self) -> Box:
        """The `Box` this describes."""
        return Box(self.width, self.height, boundary=self.boundary, walls=self._walls(),
                   partitions=self._partitions())  # fmt: skip


class CircleSpec(_VesselSpec):
    """A circular vessel centred on the origin, radius in m (`collidium.vessels.Circle`)."""

    shape: Literal["circle"]
    radius: Positive = 10.0

    def build(self) -> Circle:
        """The `Circle` this describes."""
        return Circle(self.radius, walls=self._walls(), partitions=self._partitions())


class PolygonSpec(_VesselSpec):
    """A simple polygon, its corners in m in order around it (`collidium.vessels.Polygon`)."""

    shape: Literal["polygon"]
    vertices: Annotated[list[Vector], Field(min_length=3)]

    def build(self) -> Polygon:
        """The `Polygon` this describes."""
        return Polygon(self.vertices, walls=self._walls(), partitions=self._partitions())


def _shape_of(value: Any) -> str:
    """The ``shape`` that selects a vessel's model; a table without one is a box."""
    if isinstance(value, Mapping):
        return str(value.get("shape", "box"))
    return str(getattr(value, "shape", "box"))


VesselSpec = Annotated[
    Annotated[BoxSpec, Tag("box")]
    | Annotated[CircleSpec, Tag("circle")]
    | Annotated[PolygonSpec, Tag("polygon")],
    Discriminator(_shape_of),
]


class RunSpec(_Model):
    """Time step (s, the reporting interval), default duration (s), collision mode, and the
    integrator with its tolerance (`collidium.integrators`)."""

    model_config = ConfigDict(extra="forbid", strict=True)

    dt: Positive = 0.01
    time: NonNegative = 10.0
    collisions: Literal["exact", "step", "off"] = "exact"
    integrator: Literal["adaptive", "fixed"] = "adaptive"
    tolerance: Positive = DEFAULT_TOLERANCE
    restitution: Annotated[float, Field(gt=0, le=1)] = 1.0


class _ForceSpec(_Model):
    """A force's table: its ``type`` (a name in `collidium.forces.FORCES`) and parameters. The
    models are made from the forces' own fields (`_force_spec`), which check their values."""

    type: str

    def build(self) -> Force:
        """The force this describes."""
        params = self.model_dump(exclude={"type"})
        return FORCES[self.type](**params)

    @model_validator(mode="after")
    def _valid(self) -> _ForceSpec:
        self.build()  # its InputError names the parameter (`_reason` puts it under the entry)
        return self


def _schema_type(kind: Any) -> Any:
    """The schema's type for a force parameter's annotation: floats finite, a tuple (a 2D
    vector, a pair of corners, a grid's rows) a list of its length (as TOML gives it),
    anything else (a Literal, None) as it is.

    Each field gets its own annotation: pydantic 2.6 writes a field's default into the
    ``FieldInfo`` of its annotation, which a shared alias would carry into later models."""
    if kind is float:
        return copy.deepcopy(Finite)
    if get_origin(kind) is tuple:
        items = kind.__args__
        if items[-1] is Ellipsis:  # any length: the force checks it
            return list[_schema_type(items[0])]  # type: ignore[misc]
        size = len(items)
        return Annotated[list[_schema_type(items[0])], Field(min_length=size, max_length=size)]  # type: ignore[misc]
    if get_origin(kind) in (Union, type(int | None)):
        return Union[tuple(_schema_type(arm) for arm in kind.__args__)]  # noqa: UP007
    return kind


def _plain(default: Any) -> Any:
    """A default as the schema holds it: a vector as a list."""
    return [_plain(item) for item in default] if isinstance(default, tuple) else default


def _force_spec(name: str, cls: type) -> type[_ForceSpec]:
    """The schema model of a registered force, from its parameters (a required one as
    ``Field()``: pydantic 2.6 takes ``...`` beside an annotated type for its default)."""
    fields: dict[str, Any] = {"type": (Literal[name], name)} | {
        key: (_schema_type(kind), Field() if default is dataclasses.MISSING else _plain(default))
        for key, (kind, default) in parameters(cls).items()
    }
    model: type[_ForceSpec] = create_model(
        f"{cls.__name__}Spec", __base__=_ForceSpec, __doc__=cls.__doc__, __module__=__name__,
        **fields,
    )  # fmt: skip
    globals()[model.__name__] = model  # found by name, as pickle (a process pool) looks it up
    return model


#: The schema model of each force, by its ``type`` (made once, from the registry).
_FORCE_SPECS: dict[str, type[_ForceSpec]] = {
    name: _force_spec(name, cls) for name, cls in FORCES.items()
}

if TYPE_CHECKING:
    ForceSpec = _ForceSpec
else:  # one model per registered force, chosen by ``type``
    ForceSpec = Annotated[
        Union[tuple(Annotated[model, Tag(name)] for name, model in _FORCE_SPECS.items())],  # noqa: UP007
        Discriminator("type"),
    ]


class _ObserverSpec(_Model):
    """When an observer fires: every ``every`` steps or every ``interval`` s (default every
    step), from time ``after`` (s) on."""

    every: Annotated[int, Field(ge=1)] | None = None
    interval: Positive | None = None
    after: NonNegative | None = None

    @field_validator("interval")
    @classmethod
    def _one_period(cls, value: float | None, info: ValidationInfo) -> float | None:
        if value is not None and info.data.get("every") is not None:
            raise ValueError("give either every (steps) or interval (s), not both")
        return value

    def trigger(self) -> Trigger:
        """The trigger these fields describe."""
        base: Trigger = (
            Interval(self.interval) if self.interval is not None else Every(self.every or 1)
        )
        return base if self.after is None else After(self.after, base)


class EnergySpec(_ObserverSpec):
    """`EnergySeries`: kinetic, potential, total energy, total speed and momentum over time."""

    kind: Literal["energy"] = "energy"

    def build(self) -> Observer:
        """The observer this describes."""
        return EnergySeries(self.trigger())


class SpeedsSpec(_ObserverSpec):
    """`SpeedHistogram`: speeds binned (``bins`` over ``range`` in m/s) and accumulated."""

    kind: Literal["speeds"] = "speeds"
    bins: Annotated[int, Field(ge=1, le=100_000)] = 30
    range: Vector = Field(default_factory=lambda: [0.0, 30.0])

    @field_validator("range")
    @classmethod
    def _ordered(cls, value: list[float]) -> list[float]:
        if not 0 <= value[0] < value[1]:
            raise ValueError(f"must be [low, high] with 0 <= low < high, got {value}")
        return value

    def build(self) -> Observer:
        """The observer this describes."""
        return SpeedHistogram(self.bins, (self.range[0], self.range[1]), self.trigger())


class ThermoSpec(_ObserverSpec):
    """`Thermo`: temperature, wall and virial pressure."""

    kind: Literal["thermo"] = "thermo"

    def build(self) -> Observer:
        """The observer this describes."""
        return Thermo(self.trigger())


class VirialSpec(_ObserverSpec):
    """`VirialRatio`: ``2 KE / |W|`` of the bound cluster over time."""

    kind: Literal["virial"] = "virial"

    def build(self) -> Observer:
        """The observer this describes."""
        return VirialRatio(self.trigger())


class ProfileSpec(_ObserverSpec):
    """`TemperatureProfile`: kT in ``bins`` slices across ``axis``."""

    kind: Literal["profile"] = "profile"
    bins: Annotated[int, Field(ge=1, le=10_000)] = 10
    axis: Literal["x", "y"] = "x"

    def build(self) -> Observer:
        """The observer this describes."""
        return TemperatureProfile(self.bins, self.axis, self.trigger())


class CollisionsSpec(_ObserverSpec):
    """`CollisionRate`: collision rate, mean free time and path."""

    kind: Literal["collisions"] = "collisions"

    def build(self) -> Observer:
        """The observer this describes."""
        return CollisionRate(self.trigger())


class TracerSpec(_ObserverSpec):
    """`Tracer`: paths of the listed particles (all if omitted) and their mean-square
    displacement."""

    kind: Literal["tracer"] = "tracer"
    particles: list[Annotated[int, Field(ge=0)]] | None = None

    def build(self) -> Observer:
        """The observer this describes."""
        return Tracer(self.particles, self.trigger())


class EffusionSpec(_ObserverSpec):
    """`Effusion`: crossings of the partition named ``partition`` per species, Graham's law."""

    kind: Literal["effusion"] = "effusion"
    partition: str

    def build(self) -> Observer:
        """The observer this describes."""
        return Effusion(self.partition, self.trigger())


class TrajectorySpec(_ObserverSpec):
    """`GSDWriter`: frames written to ``path`` (a .gsd file)."""

    kind: Literal["trajectory"] = "trajectory"
    path: str
    flush_seconds: NonNegative = 1.0

    @field_validator("path")
    @classmethod
    def _gsd_suffix(cls, value: str) -> str:
        if not value.endswith(".gsd"):
            raise ValueError(f"must name a .gsd file, got {value!r}")
        return value

    def build(self) -> Observer:
        """The observer this describes."""
        return GSDWriter(self.path, self.trigger(), flush_seconds=self.flush_seconds)


ObserverSpec = Annotated[
    EnergySpec
    | SpeedsSpec
    | ThermoSpec
    | ProfileSpec
    | CollisionsSpec
    | TracerSpec
    | EffusionSpec
    | TrajectorySpec
    | VirialSpec,
    Field(discriminator="kind"),
]


def build_observers(specs: Sequence[Mapping[str, Any]]) -> list[Observer]:
    """Observers from scenario ``[[observers]]`` tables (as plain data).

    Raises
    ------
    InputError
        Naming the first offending field, e.g. ``observers.1.bins: must be >= 1, got 0``.
    """
    try:
        parsed = _Observers.model_validate({"observers": plain(list(specs))})
    except ValidationError as exc:
        raise InputError(*field_and_reason(exc)) from exc
    return [spec.build() for spec in parsed.observers]


class _Observers(_Model):
    """Observer tables alone (what a checkpoint keeps of its scenario)."""

    observers: list[ObserverSpec]


@dataclass
class GroupState:
    """Arrays of one particle group: position, velocity (N, 2); mass, radius, charge (N,)."""

    position: FloatArray
    velocity: FloatArray
    mass: FloatArray
    radius: FloatArray
    charge: FloatArray


def _empty() -> GroupState:
    """A group of no particles."""
    return GroupState(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), np.zeros(0), np.zeros(0))


class ExplicitGroup(_Model):
    """Particles listed one by one; mass, radius and charge are one value or one per particle."""

    model_config = ConfigDict(extra="forbid", strict=True)

    kind: Literal["explicit"] = "explicit"
    position: Annotated[list[Vector], Field(min_length=1)]
    velocity: list[Vector] | None = None
    mass: PositivePerParticle = 1.0
    radius: NonNegativePerParticle = 0.25
    charge: FinitePerParticle = 0.0

    @field_validator("velocity", "mass", "radius", "charge")
    @classmethod
    def _same_length(cls, value: Any, info: ValidationInfo) -> Any:
        position = info.data.get("position")
        if isinstance(value, list) and position is not None and len(value) != len(position):
            raise ValueError(f"has {len(value)} entries but position has {len(position)}")
        return value

    @property
    def count(self) -> int:
        """Number of particles in the group."""
        return len(self.position)

    def generate(
        self, rng: np.random.Generator, vessel: Vessel, existing: GroupState, index: int
    ) -> GroupState:
        """The listed particles (no random draws)."""
        n = len(self.position)
        velocity = np.zeros((n, 2)) if self.velocity is None else np.array(self.velocity, float)
        return GroupState(
            np.array(self.position, dtype=np.float64),
            velocity,
            np.broadcast_to(np.asarray(self.mass, dtype=np.float64), (n,)).copy(),
            np.broadcast_to(np.asarray(self.radius, dtype=np.float64), (n,)).copy(),
            np.broadcast_to(np.asarray(self.charge, dtype=np.float64), (n,)).copy(),
        )


class RandomGroup(_Model):
    """``n`` equal disks at uniform random non-overlapping positions with uniform random velocity
    components in ``[-speed, speed]``; charge ``charge`` each, or ``+charge`` / ``-charge`` in
    equal numbers in random order with ``charges = "balanced"``. With ``region = [[x0, y0],
    [x1, y1]]`` the disks are placed only in that rectangle of the vessel (one chamber, say)."""

    model_config = ConfigDict(extra="forbid", strict=True)

    kind: Literal["random"] = "random"
    n: Annotated[int, Field(ge=0, le=MAX_GROUP_SIZE)]
    mass: Positive = 1.0
    radius: NonNegative = 0.25
    speed: Speed = 0.0
    charge: Finite = 0.0
    charges: Literal["same", "balanced"] = "same"
    region: Annotated[list[Vector], Field(min_length=2, max_length=2)] | None = None

    @field_validator("region")
    @classmethod
    def _corners(cls, value: list[list[float]] | None) -> list[list[float]] | None:
        if value is not None and not (value[0][0] < value[1][0] and value[0][1] < value[1][1]):
            raise ValueError(f"must be [[x0, y0], [x1, y1]] with x0 < x1 and y0 < y1, got {value}")
        return value

    @property
    def count(self) -> int:
        """Number of particles in the group."""
        return self.n

    def generate(
        self, rng: np.random.Generator, vessel: Vessel, existing: GroupState, index: int
    ) -> GroupState:
        """Draw positions (clear of the ``existing`` disks), then velocities, then (balanced)
        charges from ``rng``; ``index`` is the group's place in the list, named in errors."""
        position = random_positions(
            self.n, self.radius, vessel, rng, existing=vessel.wrap(existing.position),
            existing_radius=existing.radius, field=f"particles.{index}.n", region=self.region,
        )  # fmt: skip
        velocity = uniform_velocities(self.n, self.speed, rng)
        if self.charges == "balanced":
            charge = balanced_charges(self.n, self.charge, rng)
        else:
            charge = np.full(self.n, self.charge)
        full = np.full(self.n, 1.0)
        return GroupState(position, velocity, self.mass * full, self.radius * full, charge)


class RackGroup(_Model):
    """The pool-break rack: a rhombus of disks at rest in hexagonal packing, apex pointing left;
    columns of 1, 2, ..., ``rows``, ..., 2 disks (and a last single one with ``back_tip``)."""

    model_config = ConfigDict(extra="forbid", strict=True)

    kind: Literal["rack"] = "rack"
    apex: Vector = Field(default_factory=lambda: [0.0, 0.0])
    rows: Annotated[int, Field(ge=1, le=10_000)] = 15
    radius: Positive = 0.25
    mass: Positive = 1.0
    gap: NonNegative = 0.01
    charge: Finite = 0.0
    back_tip: bool = False

    @property
    def count(self) -> int:
        """Number of particles in the group: ``rows^2 - 1``, plus one with ``back_tip``."""
        return self.rows**2 - 1 + int(self.back_tip)

    def generate(
        self, rng: np.random.Generator, vessel: Vessel, existing: GroupState, index: int
    ) -> GroupState:
        """The rack's centres (no random draws); all at rest."""
        position = rhombus_rack((self.apex[0], self.apex[1]), self.rows, self.radius, self.gap,
                                self.back_tip)  # fmt: skip
        full = np.full(position.shape[0], 1.0)
        return GroupState(
            position, np.zeros_like(position), self.mass * full, self.radius * full,
            self.charge * full,
        )  # fmt: skip


class LatticeGroup(_Model):
    """``columns x rows`` equal disks on a hexagonal lattice covering the share ``packing`` of
    the plane (`collidium.initial.hexagonal_block`), from the corner ``origin`` (the vessel's
    lower-left corner by default), velocity components uniform in ``[-speed, speed]``: the start
    of a dense fluid, which random placement cannot reach past a packing of about 0.55."""

    model_config = ConfigDict(extra="forbid", strict=True)

    kind: Literal["lattice"] = "lattice"
    columns: Annotated[int, Field(ge=1, le=MAX_GROUP_SIZE)]
    rows: Annotated[int, Field(ge=1, le=MAX_GROUP_SIZE)]
    packing: Annotated[float, Field(gt=0.0, le=CLOSE_PACKING)]
    radius: Positive = 0.5
    mass: Positive = 1.0
    speed: Speed = 0.0
    charge: Finite = 0.0
    origin: Vector | None = None

    @property
    def count(self) -> int:
        """Number of particles in the group."""
        return self.columns * self.rows

    def generate(
        self, rng: np.random.Generator, vessel: Vessel, existing: GroupState, index: int
    ) -> GroupState:
        """The lattice's centres, then velocities drawn from ``rng``."""
        low = vessel.bounds[0] if self.origin is None else self.origin
        position = hexagonal_block(
            self.columns, self.rows, self.radius, self.packing, (float(low[0]), float(low[1]))
        )
        full = np.full(self.count, 1.0)
        return GroupState(
            position, uniform_velocities(self.count, self.speed, rng), self.mass * full,
            self.radius * full, self.charge * full,
        )  # fmt: skip


Group = Annotated[
    ExplicitGroup | RandomGroup | RackGroup | LatticeGroup, Field(discriminator="kind")
]

#: Model of the vessel table, by its shape, and of a wall's table, by its response (for error
#: messages).
_VESSEL_SPECS: dict[str, type[_Model]] = {
    "box": BoxSpec, "circle": CircleSpec, "polygon": PolygonSpec,
}  # fmt: skip
_WALL_SPECS: dict[str, type[_Model]] = {
    "specular": SpecularSpec, "inelastic": InelasticSpec, "thermal": ThermalSpec,
    "piston": PistonSpec,
}  # fmt: skip

#: Model of each table, by the discriminator value that selects it (for error messages).
_TAGGED: dict[str, type[_Model]] = {
    "explicit": ExplicitGroup,
    "random": RandomGroup,
    "rack": RackGroup,
    "lattice": LatticeGroup,
    "energy": EnergySpec,
    "speeds": SpeedsSpec,
    "thermo": ThermoSpec,
    "profile": ProfileSpec,
    "collisions": CollisionsSpec,
    "tracer": TracerSpec,
    "effusion": EffusionSpec,
    "trajectory": TrajectorySpec,
    "virial": VirialSpec,
    **_FORCE_SPECS,
}


class Scenario(_Model):
    """A complete simulation set-up: vessel, run settings, forces and particle groups.

    Attributes
    ----------
    name, description : str
        Label and one-line description.
    seed : int
        Seed of every random draw (group order) and of the simulation's generator.
    vessel : BoxSpec, CircleSpec or PolygonSpec
        The vessel, chosen by its ``shape``.
    run : RunSpec
        dt, default duration and collision mode.
    forces : list of force tables
        The forces acting, each a ``type`` of `collidium.forces.FORCES` and its parameters.
    particles : list of ExplicitGroup, RandomGroup, RackGroup or LatticeGroup
        Particle groups, concatenated in order.
    observers : list of observer specs
        Measurements and writers attached by `build` (``sim.observers``).
    """

    model_config = ConfigDict(extra="forbid", strict=True)

    name: str = "scenario"
    description: str = ""
    seed: Annotated[int, Field(ge=0, le=2**63 - 1)] = 0
    vessel: VesselSpec = Field(default_factory=BoxSpec)
    run: RunSpec = Field(default_factory=RunSpec)
    forces: list[ForceSpec] = Field(default_factory=list)
    particles: Annotated[list[Group], Field(min_length=1)]
    observers: list[ObserverSpec] = Field(default_factory=list)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Scenario:
        """Validate a plain mapping (as read from TOML; numpy values and tuples accepted).

        Raises
        ------
        InputError
            Naming the first offending field, e.g. ``particles.0.mass: must be > 0, got -1.0``.
        """
        if not isinstance(data, Mapping):
            raise InputError("scenario", f"expected a table of fields, got {type(data).__name__}")
        if "box" in data:
            raise InputError(
                "box",
                'the vessel is now [vessel], with shape = "box" and the same width, height and '
                "boundary",
            )
        try:
            return cls.model_validate(plain(data))
        except ValidationError as exc:
            field, reason = field_and_reason(exc)
            raise InputError(field, reason) from exc

    @classmethod
    def from_toml(cls, path: str | Path) -> Scenario:
        """Read and validate a scenario file.

        Raises
        ------
        InputError
            For a missing or unreadable file, bad TOML syntax (file and line named) or a schema
            violation (field named).
        """
        return cls.from_dict(read_toml(path))

    @classmethod
    def from_toml_string(cls, text: str, source: str = "<string>") -> Scenario:
        """Parse and validate scenario TOML text (``source`` names it in errors)."""
        return cls.from_dict(parse_toml(text, source))

    def to_dict(self) -> dict[str, Any]:
        """Plain data (Python floats, ints, str, lists, dicts); unset optional values, an empty
        observer list and an empty table of walls left out."""
        data = self.model_dump(mode="python", exclude_none=True)
        if not data["observers"]:
            del data["observers"]
        for empty in ("walls", "partitions"):
            if not data["vessel"][empty]:
                del data["vessel"][empty]
        return data

    def to_toml(self) -> str:
        """The scenario as TOML text; reading it back gives an equal scenario (floats bitwise)."""
        header = "# collidium scenario; edit it and run it with: collidium run FILE.toml\n"
        return header + dump_toml(self.to_dict())

    def with_overrides(self, overrides: Mapping[str, Any]) -> Scenario:
        """A copy with dotted-path overrides applied, validated again (see `apply_overrides`)."""
        return Scenario.from_dict(apply_overrides(self.to_dict(), overrides))

    @property
    def particle_count(self) -> int:
        """Number of particles the scenario builds (known before building)."""
        return sum(group.count for group in self.particles)

    @classmethod
    def of_state(cls, sim: Simulation, name: str | None = None) -> Scenario:
        """A scenario that builds ``sim``'s current state: its vessel, run settings and forces,
        and its particles as one explicit group (positions wrapped into a periodic box)."""
        p = sim.particles
        return cls.from_dict(
            {
                "name": name or sim.name,
                "description": f"the state of {sim.name} at t = {sim.time:.6g} s",
                "seed": sim.seed or 0,
                "vessel": sim.container.to_dict(),
                "run": {
                    "dt": sim.dt,
                    "collisions": sim.collisions,
                    "integrator": sim.integrator,
                    "tolerance": sim.tolerance,
                    "restitution": sim.restitution,
                },
                "forces": [force.to_dict() for force in sim.forces],
                "particles": [
                    {
                        "kind": "explicit",
                        "position": p.position,
                        "velocity": p.velocity,
                        "mass": uniform_or_each(p.mass),
                        "radius": uniform_or_each(p.radius),
                        "charge": uniform_or_each(p.charge),
                    }
                ],
            }
        )

    def initial_state(self) -> tuple[Vessel, Particles, list[int]]:
        """Generate the vessel and the particles.

        Returns
        -------
        vessel : Vessel
        particles : Particles
            All groups concatenated in order.
        offsets : list of int
            Index of the first particle of each group, then the total N (length groups + 1).

        Raises
        ------
        InputError
            ``particles`` when the simulation would not fit in the memory available.
        """
        _check_memory(self.particle_count)
        vessel = self.vessel.build()
        rng = np.random.default_rng(self.seed)
        fixed = {
            index: group.generate(rng, vessel, _empty(), index)
            for index, group in enumerate(self.particles)
            if not isinstance(group, RandomGroup)
        }
        groups: list[GroupState] = []
        for index, group in enumerate(self.particles):
            if index in fixed:
                groups.append(fixed[index])
                continue
            drawn = [state for k, state in enumerate(groups) if k not in fixed]
            drawn_before = _concatenate([*fixed.values(), *drawn])
            groups.append(group.generate(rng, vessel, drawn_before, index))
        state = _concatenate(groups)
        offsets = [0, *np.cumsum([len(g.mass) for g in groups]).tolist()]
        particles = Particles(
            position=state.position, velocity=state.velocity, mass=uniform_or_each(state.mass),
            radius=uniform_or_each(state.radius), charge=uniform_or_each(state.charge),
        )  # fmt: skip
        return vessel, particles, offsets

    def build(self) -> Simulation:
        """The `Simulation` this scenario describes (bitwise the same on every call).

        Raises
        ------
        InputError
            For a particle outside the vessel or overlapping another (both named by their group
            and index), a random group too dense to place, or anything `Simulation` refuses.
        """
        vessel, particles, offsets = self.initial_state()
        try:
            sim = Simulation(
                vessel, particles, forces=[force.build() for force in self.forces], dt=self.run.dt,
                collisions=self.run.collisions, seed=self.seed, name=self.name,
                integrator=self.run.integrator, tolerance=self.run.tolerance,
                restitution=self.run.restitution,
            )  # fmt: skip
        except InputError as exc:
            if exc.particles:
                raise self._placement_error(exc.particles, vessel, particles, offsets) from None
            raise InputError(_SIMULATION_FIELDS.get(exc.field, exc.field), exc.reason) from exc
        self._check_observed(particles.n, vessel)
        sim.observers.extend(spec.build() for spec in self.observers)
        return sim

    def _check_observed(self, n: int, vessel: Vessel) -> None:
        """Every particle a tracer follows and every partition an observer watches exists."""
        for k, spec in enumerate(self.observers):
            for j, index in enumerate(getattr(spec, "particles", None) or []):
                if index >= n:
                    raise InputError(
                        f"observers.{k}.particles.{j}", f"no particle {index}; there are {n}"
                    )
            if isinstance(spec, EffusionSpec):
                try:
                    vessel.partition(spec.partition)
                except InputError as exc:
                    raise InputError(f"observers.{k}.partition", exc.reason) from None

    def _placement_error(
        self, culprits: tuple[int, ...], vessel: Vessel, particles: Particles, offsets: list[int]
    ) -> InputError:
        """A `Simulation` placement error restated with the particles named by group."""
        last = culprits[-1]
        field, label = _particle_name(last, offsets, self)
        if len(culprits) == 1:
            detail = outside_detail(vessel, particles, last)
        else:
            first = _particle_name(culprits[0], offsets, self)[1]
            detail = f"overlaps {first} {overlap_detail(vessel, particles, culprits[0], last)}"
        return InputError(field, f"{_local(field, label)}{detail}", particles=culprits)


#: Where the fields named by `Simulation` and `Particles` live in a scenario.
_SIMULATION_FIELDS = {
    "position": "particles.position",
    "velocity": "particles.velocity",
    "mass": "particles.mass",
    "radius": "particles.radius",
    "charge": "particles.charge",
    "dt": "run.dt",
    "collisions": "run.collisions",
    "integrator": "run.integrator",
    "tolerance": "run.tolerance",
}


def _concatenate(states: list[GroupState]) -> GroupState:
    """The groups' arrays joined in order (empty arrays for no groups)."""
    if not states:
        return _empty()
    return GroupState(
        *(np.concatenate(arrays) for arrays in zip(*(_arrays(s) for s in states), strict=True))
    )


def _arrays(state: GroupState) -> tuple[FloatArray, ...]:
    return (state.position, state.velocity, state.mass, state.radius, state.charge)


def _particle_name(index: int, offsets: list[int], scenario: Scenario) -> tuple[str, str]:
    """Field and label of a particle: ``particles.G.position.K`` for a listed one;
    ``particles.G`` and ``particles.G disk K`` for a generated one."""
    group = int(np.searchsorted(offsets, index, side="right")) - 1
    k = index - offsets[group]
    if isinstance(scenario.particles[group], ExplicitGroup):
        path = f"particles.{group}.position.{k}"
        return path, path
    return f"particles.{group}", f"particles.{group} disk {k}"


def _local(field: str, label: str) -> str:
    """``"disk K "`` for a generated particle (its group is the field), else nothing."""
    return label.removeprefix(field).strip() + " " if label != field else ""


# --- plain data, TOML ---------------------------------------------------------------------------


#: Deepest nesting of tables and arrays a scenario may have (its own go 4 deep).
MAX_DEPTH = 16


def plain(value: Any, path: tuple[str, ...] = ()) -> Any:
    """Deep copy of ``value`` with numpy scalars and arrays and tuples made plain Python.

    Raises
    ------
    InputError
        Naming the path where tables or arrays nest more than `MAX_DEPTH` deep.
    """
    if len(path) > MAX_DEPTH:
        raise InputError(".".join(path[: MAX_DEPTH + 1]),
                         f"tables or arrays nested more than {MAX_DEPTH} deep")  # fmt: skip
    if isinstance(value, Mapping):
        return {key: plain(item, (*path, str(key))) for key, item in value.items()}
    if isinstance(value, np.ndarray):
        return plain(value.tolist(), path)
    if isinstance(value, list | tuple):
        return [plain(item, (*path, str(k))) for k, item in enumerate(value)]
    if isinstance(value, np.generic):
        return value.item()
    return copy.copy(value)


#: Memory one particle takes at the peak of building and running a simulation, bytes: about 220
#: for a million-disk gas in the exact engine, with a margin.
BYTES_PER_PARTICLE = 400


def _check_memory(count: int) -> None:
    """Refuse, before allocating anything, particles that would not fit in the memory
    available."""
    need, have = count * BYTES_PER_PARTICLE, available_memory()
    if have is not None and need > have:
        raise InputError("particles", f"{count} particles need about {need / 2**30:.3g} GiB of "
                                      f"memory; {have / 2**30:.3g} GiB is available")  # fmt: skip


def available_memory() -> int | None:
    """Bytes of memory available to a new allocation (Linux ``MemAvailable``, else the physical
    memory), or None where neither is known."""
    try:
        with open("/proc/meminfo", encoding="ascii") as info:
            for line in info:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


#: Largest scenario file read, bytes (a listing of a million explicit disks is about 60 MB).
MAX_SCENARIO_BYTES = 256 * 2**20


def read_toml(path: str | Path) -> dict[str, Any]:
    """Parse a TOML file.

    Raises
    ------
    InputError
        Naming the file, for a missing or unreadable file, one that is not a regular file (a
        folder, a pipe, a device) or is over `MAX_SCENARIO_BYTES`, or bad syntax (with line and
        column).
    """
    name = str(path)
    try:
        status = Path(path).stat()
        if not stat.S_ISREG(status.st_mode):
            raise InputError(name, "not a regular file")
        if status.st_size > MAX_SCENARIO_BYTES:
            raise InputError(name, f"larger than {MAX_SCENARIO_BYTES // 2**20} MiB")
        text = Path(path).read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise InputError(name, "no such file") from None
    except UnicodeDecodeError as exc:
        raise InputError(name, f"not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except OSError as exc:
        raise InputError(name, f"cannot read: {exc.strerror or exc}") from None
    return parse_toml(text, name)


def parse_toml(text: str, source: str) -> dict[str, Any]:
    """Parse TOML text; ``source`` names it in the `InputError` for bad syntax."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(source, f"invalid TOML: {exc}") from None
    except ValueError:  # Python refuses to read an integer of over 4300 digits
        raise InputError(source, "invalid TOML: a number with too many digits") from None
    except RecursionError:
        raise InputError(source, "invalid TOML: arrays or tables nested too deeply") from None


def _toml_scalar(value: Any) -> str:
    return tomli_w.dumps({"v": value})[len("v = ") : -1]


def _toml_value(value: Any, indent: str = "    ") -> str:
    """TOML for a value: arrays of scalars on one line, arrays of arrays one row per line."""
    if not isinstance(value, list):
        return _toml_scalar(value)
    if any(isinstance(item, list) for item in value):
        rows = "".join(f"{indent}{_toml_value(item)},\n" for item in value)
        return f"[\n{rows}]"
    return "[" + ", ".join(_toml_scalar(item) for item in value) + "]"


def _toml_table(table: Mapping[str, Any]) -> str:
    return "".join(f"{key} = {_toml_value(value)}\n" for key, value in table.items())


def dump_toml(data: Mapping[str, Any]) -> str:
    """TOML text for scenario data: top-level values, then tables, then arrays of tables.

    Parameters
    ----------
    data : mapping
        Values are str, bool, int, float, lists of those or of lists, tables (nested tables
        follow their parent, ``[vessel.walls.left]``) and lists of tables (the shape of
        `Scenario.to_dict`).
    """
    scalars = {k: v for k, v in data.items() if not isinstance(v, Mapping) and not _is_tables(v)}
    chunks = [_toml_table(scalars)]
    for key, value in data.items():
        if isinstance(value, Mapping):
            chunks.append(_toml_section(key, value))
        elif _is_tables(value):
            chunks.extend(f"\n[[{key}]]\n{_toml_table(item)}" for item in value)
    return "".join(chunks)


def _toml_section(path: str, table: Mapping[str, Any]) -> str:
    """``[path]`` with the table's values, then its nested tables as ``[path.key]`` and its
    lists of tables as ``[[path.key]]``."""
    values = {k: v for k, v in table.items() if not isinstance(v, Mapping) and not _is_tables(v)}
    nested = (_toml_section(f"{path}.{k}", v) for k, v in table.items() if isinstance(v, Mapping))
    listed = (
        f"\n[[{path}.{k}]]\n{_toml_table(item)}"
        for k, v in table.items()
        if _is_tables(v)
        for item in v
    )
    return f"\n[{path}]\n{_toml_table(values)}" + "".join(listed) + "".join(nested)


def _is_tables(value: Any) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, Mapping) for v in value)


# --- overrides ----------------------------------------------------------------------------------


def apply_overrides(data: Mapping[str, Any], overrides: Mapping[str, Any]) -> dict[str, Any]:
    """Set values at dotted paths (``"run.dt"``, ``"particles.0.n"``), then validate the result.

    Parameters
    ----------
    data : mapping
        Scenario data, e.g. from `Scenario.to_dict` or a TOML file (not modified).
    overrides : mapping of str to value
        Dotted path -> new value. List entries are addressed by index; a missing table on the way
        (``vessel`` in ``vessel.width``) is created.

    Returns
    -------
    dict
        The updated scenario data, validated by the schema (as `Scenario.to_dict` gives it).

    Raises
    ------
    InputError
        For a path that leads nowhere (the path named) or a value the schema refuses (the field
        named).
    """
    result = plain(data)
    for key, value in overrides.items():
        _set_path(result, key, plain(value))
    return Scenario.from_dict(result).to_dict()


def _set_path(data: dict[str, Any], key: str, value: Any) -> None:
    parts = key.split(".")
    if not all(parts):
        raise InputError(key, "not a field path (expected names and indices joined by dots)")
    node: Any = data
    for depth, part in enumerate(parts):
        here = ".".join(parts[: depth + 1])
        last = depth == len(parts) - 1
        if isinstance(node, list):
            if not part.isdigit():
                raise InputError(here, f"expected a list index 0..{len(node) - 1}")
            index = int(part)
            if index >= len(node):
                raise InputError(here, f"no entry {index}; there are {len(node)}")
            if last:
                node[index] = value
            else:
                node = node[index]
        elif isinstance(node, dict):
            if last:
                node[part] = value
            else:
                node = node.setdefault(part, {})
        else:
            raise InputError(here, f"{'.'.join(parts[:depth])} is a value, not a table or list")


# --- validation errors as one line --------------------------------------------------------------


def field_and_reason(exc: ValidationError) -> tuple[str, str]:
    """The first problem of a pydantic validation error as ``(dotted field path, reason)``.

    The discriminator values that pydantic inserts in locations (``particles.0.random.n``) are
    dropped: ``("particles.0.n", "must be >= 0, got -3")``.
    """
    errors = exc.errors(include_url=False)
    if not errors:
        return "scenario", str(exc)
    error = errors[0]
    field, reason = _reason(error)
    if len(errors) > 1:
        reason += f" (and {len(errors) - 1} more problem{'s' if len(errors) > 2 else ''})"
    return field, reason


def describe(exc: ValidationError) -> str:
    """One line ``field.path: reason`` for a pydantic validation error."""
    field, reason = field_and_reason(exc)
    return f"{field}: {reason}"


def _is_tag(loc: tuple[int | str, ...], k: int) -> bool:
    """Whether ``loc[k]`` is a discriminator value pydantic inserted: a list entry's kind, the
    vessel's shape or a wall's response."""
    if k == 0:
        return False
    before = loc[k - 1]
    return (
        (isinstance(before, int) and loc[k] in _TAGGED)
        or (before == "vessel" and k == 1 and loc[k] in _VESSEL_SPECS)
        or (k >= 2 and loc[k - 2] == "walls" and loc[k] in _WALL_SPECS)
    )


def _clean_loc(loc: tuple[int | str, ...]) -> list[int | str]:
    return [part for k, part in enumerate(loc) if not _is_tag(loc, k)]


#: pydantic's bound errors: (the comparison, the context key holding the bound).
_BOUNDS = {
    "greater_than": (">", "gt"),
    "greater_than_equal": (">=", "ge"),
    "less_than": ("<", "lt"),
    "less_than_equal": ("<=", "le"),
}


def _reason(error: Any) -> tuple[str, str]:
    kind = error["type"]
    loc = _clean_loc(error["loc"])
    ctx = error.get("ctx") or {}
    got = _short(error.get("input"))
    path = ".".join(str(part) for part in loc) or "scenario"
    if kind == "extra_forbidden":
        allowed = _allowed_fields(error["loc"][:-1])
        hint = f"; allowed: {', '.join(allowed)}" if allowed else ""
        return path, f"unknown field{hint}"
    if kind == "missing":
        return path, "required field is missing"
    if kind == "union_tag_invalid" and loc == ["vessel"]:
        return "vessel.shape", f"unknown value {ctx.get('tag')!r}; choose from {', '.join(VESSELS)}"
    if kind in ("union_tag_not_found", "union_tag_invalid"):
        tag = str(ctx.get("discriminator", "kind")).strip("'")
        observer = bool(loc) and loc[0] == "observers"
        expected = [
            name
            for name, model in _TAGGED.items()
            if tag in model.model_fields and issubclass(model, _ObserverSpec) == observer
        ]
        what = "missing" if kind == "union_tag_not_found" else f"unknown value {ctx.get('tag')!r}"
        return f"{path}.{tag}", f"{what}; choose from {', '.join(expected)}"
    if kind in _BOUNDS:
        sign, key = _BOUNDS[kind]
        return path, f"must be {sign} {_num(ctx[key])}, got {got}"
    if kind == "too_short":
        return path, f"needs at least {ctx['min_length']} entries, got {ctx['actual_length']}"
    if kind == "too_long":
        return path, f"takes at most {ctx['max_length']} entries, got {ctx['actual_length']}"
    if kind == "finite_number":
        return path, f"must be a finite number, got {got}"
    if kind == "value_error":
        problem = ctx.get("error")
        if isinstance(problem, InputError) and loc[:1] == ["forces"]:  # a force's own check
            return f"{path}.{parameter_path(problem)}", problem.reason
        return path, str(problem or error["msg"])
    message = error["msg"]
    message = message[0].lower() + message[1:]
    return path, f"{message}, got {got}" if "input" in error else message


def _num(value: Any) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _allowed_fields(loc: tuple[int | str, ...]) -> list[str]:
    """Field names of the model at a raw pydantic location (empty when it cannot be told)."""
    model: type[BaseModel] | None = Scenario
    for k, part in enumerate(loc):
        if isinstance(part, int):
            model = None  # a list entry: its kind (the next part) decides the model
        elif _is_tag(loc, k):
            tables = _TAGGED if isinstance(loc[k - 1], int) else _VESSEL_SPECS
            model = (_WALL_SPECS if k >= 2 and loc[k - 2] == "walls" else tables)[str(part)]
        elif k == 0 or isinstance(loc[k - 1], str):
            fields = model.model_fields if model is not None else {}
            if part not in fields:
                return []
            model = _model_of(fields[part].annotation)
    return list(model.model_fields) if model is not None else []


def _model_of(annotation: Any) -> type[BaseModel] | None:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    return None
