"""The force seam: the `Force` protocol, the registry of forces by name, and `ForceField`.

Every force, a pair force (`Coulomb`, `Newton`) or an external field (`Gravity`,
`UniformField`), gives per-particle forces, energies and virials (HOOMD's ``md.force.Force``),
says how fast its energies change (for the adaptive integrator's substeps) and writes itself as
a table with a ``type`` (for scenario files and checkpoints). Front ends find forces by that
name in `FORCES`, never by their class: a new force is one module that registers itself.
"""

from __future__ import annotations

import dataclasses
import math
import typing
from collections.abc import Mapping
from typing import Any, ClassVar, Protocol, TypeVar, runtime_checkable

import numpy as np

from collidium.errors import InputError, SimulationError
from collidium.kernels.sums import ordered_sum
from collidium.state import FloatArray, Particles
from collidium.vessels import Vessel


@runtime_checkable
class Force(Protocol):
    """What every force is to the front ends (a frozen dataclass of parameters): a name, a check
    of the set-up and a table. It acts either on the positions (`PositionForce`) or on the
    velocities (`VelocityForce`).

    Attributes
    ----------
    name : str
        The name in `FORCES`, the scenario file's ``type`` and checkpoints.
    """

    name: ClassVar[str]

    def check(self, particles: Particles, vessel: Vessel) -> None:
        """Refuse a set-up this force cannot act in (`InputError` naming the field)."""

    def to_dict(self) -> dict[str, object]:
        """The parameters as a scenario table, with ``type`` = `name`."""


@runtime_checkable
class PositionForce(Force, Protocol):
    """A force of the positions, with a potential energy: the kicks of kick-drift-kick."""

    def compute(
        self,
        particles: Particles,
        vessel: Vessel,
        force: FloatArray,
        energy: FloatArray,
        virial: FloatArray,
        work: dict[str, np.ndarray],
        energies: bool,
    ) -> None:
        """Write the force on each particle into ``force`` (N, 2), in N, and if ``energies``
        each particle's share of the potential energy into ``energy`` (N,) and of the pair
        virial ``sum r_ij . F_ij`` into ``virial`` (N,), both in J (their sums are the totals).
        Without ``energies`` (a kick needs the forces alone) a force may leave those two
        unwritten, but its forces are bitwise the same. ``work`` keeps buffers from call to call
        (empty on the first)."""

    def stiffness(self, particles: Particles, vessel: Vessel, acceleration: FloatArray) -> float:
        """``S`` in J^2/s^4: a leapfrog step h errs on the energy of the part hardest to follow
        by about ``sqrt(S) h^2`` (`collidium.integrators`); 0 for a uniform force, which leapfrog
        follows exactly. ``acceleration`` (N, 2) is the total of the last evaluation."""

    @property
    def fall(self) -> tuple[float, float] | None:
        """The acceleration (x, y) in m/s^2 that the force gives every particle alike, whatever
        its mass and charge (a uniform gravity), or None. A drift mode that `carries_fall`
        (`collidium.collisions.Drift`) flies the particles on its parabolas instead of kicking
        them."""


@runtime_checkable
class VelocityForce(Force, Protocol):
    """A force of the velocities (a magnetic field, drag, friction, a thermostat), with no
    potential: the integrators apply its exact flow on the velocities for half a substep before
    each kick-drift-kick and half after (a time-symmetric splitting; `ForceField.advance`)."""

    def advance(
        self, particles: Particles, vessel: Vessel, h: float, rng: np.random.Generator
    ) -> float:
        """Change the velocities in place as the force alone would in ``h`` seconds; returns the
        energy that gave the particles, J (negative for drag: the heat it took)."""

    def rate(self, particles: Particles, vessel: Vessel) -> float:
        """The fastest rate at which the force turns or damps a velocity, 1/s (``|q B| / m``,
        ``gamma / m``): the adaptive integrator keeps a substep within ``tolerance`` of its
        inverse; 0 where the flow is exact whatever the substep."""


@runtime_checkable
class DirectPairForce(PositionForce, Protocol):
    """A position force that may be an inverse-distance pair sum the compiled substeps can do
    (`collidium.kernels.substeps`)."""

    def direct_term(self, particles: Particles, vessel: Vessel) -> tuple[str, float, float] | None:
        """``(the particles' property that holds the sources, coupling, squared softening in
        m^2)`` when the force is exactly the direct inverse-distance sum of
        `collidium.kernels.pairwise` here, else None."""


@runtime_checkable
class PairLawForce(PositionForce, Protocol):
    """A position force between pairs of particles by an inverse-distance law, however it is
    summed: what the kick timing of their contacts needs (`collidium.kernels.kick_timing`)."""

    def pair_law(self, particles: Particles) -> tuple[FloatArray, float, float]:
        """``(sources (N,), coupling, squared softening in m^2)`` of the law
        ``U_ij = c s_i s_j / sqrt(r^2 + eps^2)`` (`collidium.kernels.pairwise`)."""

    def follows_law(self, particles: Particles, vessel: Vessel) -> bool:
        """Whether the force summed here is exactly the gradient of the law's energy (summed
        directly, nothing capping it): what the contacts' modified-energy term of
        `collidium.kernels.kick_timing` needs."""


@runtime_checkable
class UniformPositionForce(PositionForce, Protocol):
    """A position force that is a constant force on each particle (a uniform field), which the
    compiled substeps can kick with (`collidium.kernels.substeps`)."""

    def uniform_force(self, particles: Particles) -> FloatArray:
        """The force on each particle (N, 2), N: the same at every position."""


@runtime_checkable
class TurningForce(VelocityForce, Protocol):
    """A velocity force that turns each velocity at a constant rate inside a rectangle (a
    magnetic field), which the compiled substeps can apply (`collidium.kernels.substeps`)."""

    def cyclotron(self, particles: Particles) -> FloatArray:
        """Each particle's signed rate of turning (N,), rad/s, where the force acts; a
        velocity turns by ``-rate h`` in ``h`` seconds (clockwise for a positive rate)."""

    def bounds(self) -> FloatArray:
        """Where the force acts: ``(left, bottom, right, top)`` in m, infinite for the plane."""


@runtime_checkable
class DampingForce(VelocityForce, Protocol):
    """A velocity force that damps each velocity at a constant rate (linear drag), which the
    compiled substeps can apply (`collidium.kernels.substeps`)."""

    def damping(self, particles: Particles) -> FloatArray:
        """Each particle's rate of damping (N,), 1/s: a velocity falls by ``exp(-rate h)`` in
        ``h`` seconds."""


#: Every force by its name (filled as the force modules are imported).
FORCES: dict[str, type[Force]] = {}

ForceType = TypeVar("ForceType", bound=type)


def register(cls: ForceType) -> ForceType:
    """Class decorator: put a force into `FORCES` under its ``name``."""
    FORCES[cls.name] = cls  # type: ignore[attr-defined]
    return cls


def parameters(cls: type) -> dict[str, tuple[Any, Any]]:
    """A registered force's parameters: name -> (type, default), in the order of its fields
    (the scenario schema is made from them)."""
    hints = typing.get_type_hints(cls)
    return {
        field.name: (hints[field.name], field.default)
        for field in dataclasses.fields(cls)
        if field.init
    }


def force_from_dict(data: Mapping[str, Any], where: str = "forces") -> Force:
    """The force a scenario table describes (``type`` and parameters), as in a checkpoint.

    Raises
    ------
    InputError
        For an unknown ``type`` or parameter, or a parameter the force refuses, named under
        ``where`` (e.g. ``forces.0.k``).
    """
    kind = data.get("type")
    if kind not in FORCES:
        raise InputError(
            f"{where}.type", f"unknown force {kind!r}; choose from {', '.join(FORCES)}"
        )
    cls = FORCES[kind]
    allowed = parameters(cls)
    for key in data:
        if key != "type" and key not in allowed:
            raise InputError(f"{where}.{key}", f"unknown field; allowed: {', '.join(allowed)}")
    try:
        return cls(**{key: value for key, value in data.items() if key != "type"})
    except InputError as exc:
        raise InputError(f"{where}.{parameter_path(exc)}", exc.reason) from None


def parameter_path(error: InputError) -> str:
    """The parameter a force's own check named (``potential.1.1`` of
    ``forces.field_map.potential.1.1``), to put under the force's place in a list."""
    return error.field.split(".", 2)[-1]


# --- parameter checks shared by the forces -----------------------------------------------------


def check_finite(force: str, field: str, value: float) -> None:
    """Refuse a value that is not a finite number (field ``forces.<force>.<field>``)."""
    if not (isinstance(value, int | float) and math.isfinite(value)):
        raise InputError(f"forces.{force}.{field}", f"must be a finite number, got {value!r}")


def check_at_least(force: str, field: str, value: float, low: float = 0.0) -> None:
    """Refuse a value below ``low`` (or not a finite number)."""
    check_finite(force, field, value)
    if value < low:
        raise InputError(f"forces.{force}.{field}", f"must be >= {low:g}, got {value!r}")


def check_vector(force: str, field: str, value: Any) -> tuple[float, float]:
    """A finite 2D vector as a tuple of floats (a list or array is accepted)."""
    try:
        x, y = (float(c) for c in value)
    except (TypeError, ValueError):
        raise InputError(
            f"forces.{force}.{field}", f"must be two numbers (x, y), got {value!r}"
        ) from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise InputError(f"forces.{force}.{field}", f"must be finite, got {value!r}")
    return x, y


def check_rectangle(
    force: str, field: str, value: Any
) -> tuple[tuple[float, float], tuple[float, float]]:
    """Two finite corners (lower left, upper right) as tuples, the second above and right of
    the first."""
    try:
        low, high = value
    except (TypeError, ValueError):
        raise InputError(
            f"forces.{force}.{field}", f"must be two corners [[x0, y0], [x1, y1]], got {value!r}"
        ) from None
    low, high = check_vector(force, field, low), check_vector(force, field, high)
    if not (low[0] < high[0] and low[1] < high[1]):
        raise InputError(
            f"forces.{force}.{field}", f"the second corner must be above and right of the "
            f"first, got {value!r}"
        )  # fmt: skip
    return low, high


@dataclasses.dataclass(frozen=True, eq=False)
class CompiledForces:
    """The forces as the compiled substeps take them (`ForceField.compiled`).

    Attributes
    ----------
    source : str or None
        The particles' property that holds the pair force's sources ("charge" or "mass"), None
        without a pair force.
    coupling, softening2 : float
        The pair force's coupling (N m^2 per source squared) and squared softening (m^2); 0
        without one.
    uniform : ndarray, shape (N, 2) or (0, 2)
        The uniform field's force on each particle, N (none: empty).
    fall : ndarray, shape (2,) or (0,)
        The acceleration of the uniform field where the drift carries it (a gravity), m/s^2:
        the compiled substeps then kick with it, and it is not in the field's accelerations;
        empty where the field (if any) is in them.
    turn : ndarray, shape (N,) or (0,)
        The magnetic field's signed cyclotron frequencies, rad/s (none: empty).
    region : ndarray, shape (4,)
        Where the magnetic field acts: left, bottom, right, top, m.
    damp : ndarray, shape (N,) or (0,)
        The drag's damping rates, 1/s (none: empty).
    """

    source: str | None
    coupling: float
    softening2: float
    uniform: FloatArray
    fall: FloatArray
    turn: FloatArray
    region: FloatArray
    damp: FloatArray


_WHOLE_PLANE = np.array([-np.inf, -np.inf, np.inf, np.inf])


@dataclasses.dataclass(frozen=True)
class _CompiledParts:
    """The forces by the part the compiled substeps give them, each None if absent, and whether
    the drift carries the uniform field."""

    pair: DirectPairForce | None
    uniform: UniformPositionForce | None
    carried: bool
    turning: TurningForce | None
    damping: DampingForce | None

    @classmethod
    def of(
        cls,
        position: tuple[PositionForce, ...],
        velocity: tuple[VelocityForce, ...],
        carried: tuple[bool, ...],
    ) -> _CompiledParts | None:
        """The parts of the forces, or None if there is more than one of a kind, a force of
        another kind or no force at all (`ForceField.compiled`)."""
        pairs = [f for f in position if isinstance(f, DirectPairForce)]
        uniform = [f for f in position if isinstance(f, UniformPositionForce)]
        turning = [f for f in velocity if isinstance(f, TurningForce)]
        damping = [f for f in velocity if isinstance(f, DampingForce)]
        kinds = (pairs, uniform, turning, damping)
        if (
            sum(len(kind) for kind in kinds) != len(position) + len(velocity)
            or max(len(kind) for kind in kinds) > 1
            or not (position or velocity)
        ):
            return None
        carries = any(carried)  # only a uniform field (a gravity) can be carried
        return cls(_one(pairs), _one(uniform), carries, _one(turning), _one(damping))


_Kind = TypeVar("_Kind")


def _one(forces: list[_Kind]) -> _Kind | None:
    """The one force of a list of at most one, or None."""
    return forces[0] if forces else None


def _refuse_infinite(acceleration: FloatArray) -> None:
    """One line naming the first particle whose acceleration (N, 2) overflowed (a force on a
    mass too small to move by it)."""
    # A reduction on the hot path (any inf or NaN makes the sum one); the search only on failure.
    with np.errstate(invalid="ignore", over="ignore"):  # inf - inf is the NaN looked for
        total = float(acceleration.sum())
    if not math.isfinite(total):
        i = int(np.argmin(np.isfinite(acceleration).all(axis=1)))
        raise SimulationError(
            f"particle {i}: the force on it gives an infinite acceleration (its mass is too "
            "small for the force)"
        )


@dataclasses.dataclass(frozen=True, eq=False)
class Evaluation:
    """What a `ForceField` evaluation left (`ForceField.saved`): the accelerations (N, 2) in
    m/s^2, the potential and the pair virial in J if ``with_energies``, the positions (N, 2) in m
    it was made at, and whether the energies were read since the last step's end."""

    acceleration: FloatArray
    potential: float
    virial: float
    with_energies: bool
    at: FloatArray | None
    read: bool


class ForceField:
    """All forces of a simulation: total acceleration and potential energy of the position
    forces, with reused buffers, and the flow of the velocity forces.

    The kicks need the forces alone; the energies and virials are summed when read (`potential`,
    `virial`: an observer, the summary, the adaptive integrator once per interval). An
    evaluation that closes a step sums them with the forces, at little more cost, when those of
    the step before were read: an observer that reads every step then costs no second pass,
    and one that reads every hundredth step about two in a hundred.

    Parameters
    ----------
    forces : sequence of Force
        The forces acting; empty for free flight.
    rng : numpy.random.Generator, optional
        Where a thermostat draws its kicks (the simulation's generator, saved in checkpoints).
    carry_fall : bool
        Whether the drift flies the particles on the parabolas of the forces that give every
        one the same acceleration (`PositionForce.fall`, a uniform gravity): those forces then
        count in the energies but give no kicks (`fall`, `kicks`).
    """

    def __init__(
        self,
        forces: tuple[Force, ...],
        rng: np.random.Generator | None = None,
        carry_fall: bool = False,
    ) -> None:
        self.forces = tuple(forces)
        self._position = tuple(f for f in self.forces if isinstance(f, PositionForce))
        self._velocity = tuple(f for f in self.forces if isinstance(f, VelocityForce))
        #: Per position force: whether the drift carries it (no kicks).
        self._carried = tuple(carry_fall and f.fall is not None for f in self._position)
        #: The forces by the part the compiled substeps give them (`compiled`; a protocol
        #: check is slow), or None where a force is none of those parts.
        self._compiled = _CompiledParts.of(self._position, self._velocity, self._carried)
        self._pair_laws = tuple(f for f in self._position if isinstance(f, PairLawForce))
        #: Whether the forces are of the kinds whose modified energy is known, with a pair law
        #: among them (`keeps_modified_energy`).
        self._modified_energy_known = (
            bool(self._pair_laws)
            and not self._velocity
            and not any(self._carried)
            and all(isinstance(f, PairLawForce | UniformPositionForce) for f in self._position)
        )
        self._fall = np.zeros(2)
        for force, carried in zip(self._position, self._carried, strict=True):
            if carried:
                self._fall += force.fall  # type: ignore[arg-type]
        self._rng = np.random.default_rng() if rng is None else rng
        self._work: list[dict[str, np.ndarray]] = [{} for _ in self._position]
        self._force = np.empty((0, 2))
        self._energy = np.empty(0)
        self._virial = np.empty(0)
        self._evaluated_at: FloatArray | None = None
        #: Whether the last evaluation summed the energies (`_potential`, `_virial_sum`).
        self._with_energies = False
        #: Whether the energies were read since the last evaluation that closed a step.
        self._read = False
        self._acceleration = np.empty((0, 2))
        self._potential = 0.0
        self._virial_sum = 0.0

    @property
    def acceleration(self) -> FloatArray:
        """Acceleration (N, 2) in m/s^2 from the last `evaluate`."""
        return self._acceleration

    @property
    def active(self) -> bool:
        """True when at least one force acts."""
        return bool(self.forces)

    @property
    def kicks(self) -> bool:
        """True when a force acts that the drift does not carry: the integrator must then kick
        or apply the velocity forces' flow."""
        return bool(self._velocity) or not all(self._carried)

    @property
    def falls_alone(self) -> bool:
        """True when the field is one force that the drift carries (a uniform gravity alone):
        its potential energy is then ``-sum m_i fall . x_i`` (`collidium.forces.uniform`)."""
        return len(self.forces) == 1 and self._carried == (True,)

    @property
    def fall(self) -> FloatArray:
        """The acceleration (2,) in m/s^2 that the drift carries (zero if it carries none)."""
        return self._fall

    def evaluate(
        self, particles: Particles, vessel: Vessel, closes_step: bool = False
    ) -> FloatArray:
        """Total acceleration (N, 2) in m/s^2 of the position forces at the current positions,
        less the `fall` the drift carries. An evaluation that ``closes_step`` (the last of an
        integrator's step) also sums the potential and the virial of every force when those of
        the step before were read."""
        energies = closes_step and self._read
        if closes_step:
            self._read = False
        return self._evaluate(particles, vessel, energies)

    def refresh(self, particles: Particles, vessel: Vessel) -> FloatArray:
        """`evaluate` for a run's start: the particles may have changed since the last run. The
        energies are summed too if those of the last step were read, as they will likely be
        again: a run of one step at a time (the viewer's ticks) then pays no second evaluation
        for them."""
        return self._evaluate(particles, vessel, self._read)

    def _evaluate(self, particles: Particles, vessel: Vessel, energies: bool) -> FloatArray:
        n = particles.n
        if self._force.shape[0] != n:
            self._force = np.empty((n, 2))
            self._energy = np.empty(n)
            self._virial = np.empty(n)
            self._acceleration = np.empty((n, 2))
        self._acceleration[...] = 0.0
        potential = virial = 0.0
        # Overflowing forces (infinite, or opposite infinities summed to NaN) are refused below.
        with np.errstate(over="ignore", invalid="ignore"):
            for force, work, carried in zip(self._position, self._work, self._carried, strict=True):
                force.compute(particles, vessel, self._force, self._energy, self._virial, work,
                              energies)  # fmt: skip
                if not carried:
                    self._acceleration += self._force
                if energies:  # in particle order, as the compiled intervals sum them
                    potential += ordered_sum(self._energy)
                    virial += ordered_sum(self._virial)
            np.divide(self._acceleration, particles.mass[:, None], out=self._acceleration)
        _refuse_infinite(self._acceleration)
        self._potential = potential
        self._virial_sum = virial
        self._with_energies = energies
        self._evaluated_at = particles.position.copy()
        return self._acceleration

    def saved(self) -> Evaluation:
        """The last evaluation, for `restore` to put back when the particles are put back where
        it was made (an interval taken again) instead of evaluating the same forces again."""
        # The accelerations are written in place by the next evaluation; the positions it was
        # made at are a fresh array at each, so they are kept as they are.
        return Evaluation(
            self._acceleration.copy(), self._potential, self._virial_sum, self._with_energies,
            self._evaluated_at, self._read,
        )  # fmt: skip

    def restore(self, saved: Evaluation) -> None:
        """Make ``saved`` (from `saved`, with the particles as many) the last evaluation again."""
        self._acceleration[...] = saved.acceleration
        self._potential = saved.potential
        self._virial_sum = saved.virial
        self._with_energies = saved.with_energies
        self._evaluated_at = saved.at
        self._read = saved.read

    def compiled(self, particles: Particles, vessel: Vessel) -> CompiledForces | None:
        """The forces as the compiled substeps take them (`collidium.kernels.substeps`), or
        None unless they are at most one direct inverse-distance pair sum
        (`DirectPairForce.direct_term`), one uniform field (`UniformPositionForce`, carried by
        the drift or not), one magnetic field (`TurningForce`) and one linear drag
        (`DampingForce`), and at least one of them."""
        parts = self._compiled
        if parts is None:
            return None
        term = ("charge", 0.0, 0.0)  # no pair force: its sources are all 0
        if parts.pair is not None:
            found = parts.pair.direct_term(particles, vessel)
            if found is None:
                return None
            term = found
        name, coupling, softening2 = term
        uniform, turning, damping = parts.uniform, parts.turning, parts.damping
        return CompiledForces(
            name if parts.pair is not None else None,
            coupling,
            softening2,
            np.empty((0, 2)) if uniform is None else uniform.uniform_force(particles),
            self._fall.copy() if parts.carried else np.empty(0),
            np.empty(0) if turning is None else turning.cyclotron(particles),
            _WHOLE_PLANE if turning is None else turning.bounds(),
            np.empty(0) if damping is None else damping.damping(particles),
        )

    def pair_laws(self, particles: Particles) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The inverse-distance pair forces' laws (`PairLawForce.pair_law`): their sources
        (L, N), couplings (L,) and squared softenings (L,), m^2."""
        laws = [force.pair_law(particles) for force in self._pair_laws]
        sources = np.array([law[0] for law in laws]).reshape(len(laws), particles.n)
        couplings = np.array([law[1] for law in laws], dtype=float)
        softenings2 = np.array([law[2] for law in laws], dtype=float)
        return sources, couplings, softenings2

    def follows_laws(self, particles: Particles, vessel: Vessel) -> bool:
        """Whether every inverse-distance pair force is summed as its law's gradient
        (`PairLawForce.follows_law`)."""
        return all(force.follows_law(particles, vessel) for force in self._pair_laws)

    def keeps_modified_energy(self, particles: Particles, vessel: Vessel) -> bool:
        """Whether the substeps' modified energy is known here, so that the adaptive integrator
        keeps it where the substep changes (`collidium.kernels.modified_energy`): the position
        forces are pair laws summed as their gradients (`follows_laws`) and uniform fields,
        whose Hessian is 0, the drift carries none of them, and no velocity force acts. Without
        a pair law there is nothing to keep: leapfrog follows uniform fields exactly, and their
        modified energy differs from the energy by a constant."""
        return self._modified_energy_known and self.follows_laws(particles, vessel)

    def stiffness(self, particles: Particles, vessel: Vessel) -> float:
        """``S`` of all forces at the current state, in J^2/s^4: the largest of the forces'
        (`PositionForce.stiffness`, given the acceleration of the last `evaluate`)."""
        return max(
            (force.stiffness(particles, vessel, self._acceleration) for force in self._position),
            default=0.0,
        )

    def rate(self, particles: Particles, vessel: Vessel) -> float:
        """The fastest rate of the velocity forces, 1/s (`VelocityForce.rate`; 0 without)."""
        return max((force.rate(particles, vessel) for force in self._velocity), default=0.0)

    def advance(self, particles: Particles, vessel: Vessel, h: float, first: bool) -> float:
        """Apply the velocity forces for ``h`` seconds, one after the other: in reverse order
        for the ``first`` half of a substep and in order for the second, so that the substep is
        time-symmetric. Returns the energy they gave the particles, J."""
        forces = reversed(self._velocity) if first else self._velocity
        return sum((force.advance(particles, vessel, h, self._rng) for force in forces), 0.0)

    def potential(self, particles: Particles, vessel: Vessel) -> float:
        """Potential energy in J at the current positions (from the last evaluation if it
        summed the energies there, else summed now)."""
        self._refresh(particles, vessel)
        return self._potential

    def virial(self, particles: Particles, vessel: Vessel) -> float:
        """Pair virial ``sum_{i<j} r_ij . F_ij`` in J at the current positions (of the pair
        forces before any acceleration cap; minimum image in a periodic vessel)."""
        self._refresh(particles, vessel)
        return self._virial_sum

    def _refresh(self, particles: Particles, vessel: Vessel) -> None:
        self._read = True
        if not self.active:
            self._potential = self._virial_sum = 0.0
        elif (
            not self._with_energies
            or self._evaluated_at is None
            or not np.array_equal(self._evaluated_at, particles.position)
        ):
            self._evaluate(particles, vessel, energies=True)
