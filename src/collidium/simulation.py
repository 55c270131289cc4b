"""`Simulation`: owns the state, the vessel, the forces, the integrator and the observers.

Run loop, one step of length dt (the reporting interval):

1. the integrator (`collidium.integrators`) advances the state by dt: kick ``v += a h/2``, drift
   for h (the collision mode: exact events, the seed's step method, or pass-through, reflecting
   from walls or wrapping in a periodic box), forces at the new positions, kick ``v += a h/2``;
   ``"adaptive"`` takes as many substeps h as the forces need, ``"fixed"`` one of h = dt, and
   without forces both are a single drift;
2. ``time += dt``, ``steps += 1``;
3. audit: a NaN/infinity or a particle outside the vessel stops the run with `SimulationError`;
4. observers whose trigger fires (``trigger(sim)``) are updated.

Where the integrator can (`Integrator.fly`: exact collisions without forces or under a uniform
gravity alone, or a small scene under a direct pair force), the steps before the next observer that
reads the state are taken in one compiled call, bit for bit as one by one; observers that read no
more than the energies, virial, momentum, total speed and tallies (``take_flown``:
`collidium.observers.Flown`) get those of each of their steps from it.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from collidium.collisions import COLLISION_MODES, CollisionMode, FlightRecord, Tally, make_drift
from collidium.errors import InputError, SimulationError
from collidium.forces import Force, ForceField, PositionForce, force_from_dict
from collidium.integrators import (
    DEFAULT_TOLERANCE,
    INTEGRATORS,
    Integrator,
    IntegratorName,
    make_integrator,
)
from collidium.io.checkpoint import read_checkpoint, saved_vessel, write_checkpoint
from collidium.kernels import sums
from collidium.kernels.audit import first_invalid, first_past_face
from collidium.kernels.cells import first_overlap, grid_shape, grid_window, window_sides
from collidium.observers.base import Every, Flown, Observer, Trigger, fires_at, foreseeable
from collidium.state import (
    PROPERTIES,
    BoolArray,
    FloatArray,
    IntArray,
    Particles,
    as_given,
    writable,
)
from collidium.vessels import Vessel, vessel_from_dict
from collidium.vessels.walls import check_restitution

#: Most steps one `Simulation.run` call accepts (a guard against a mistyped time or dt).
MAX_STEPS = 1e12

#: Most steps the integrator flies in one compiled call (`Integrator.fly`): a Ctrl-C waits for
#: the call to end, a fraction of a second for a small charged scene.
MOST_FLOWN = 1000


@dataclass(frozen=True)
class Energy:
    """Energies in J."""

    kinetic: float
    potential: float

    @property
    def total(self) -> float:
        """Kinetic plus potential energy in J."""
        return self.kinetic + self.potential


@dataclass(frozen=True)
class PistonState:
    """A piston now (`Simulation.piston`).

    Attributes
    ----------
    wall : str
        The box wall it is.
    position, velocity : float
        Its face's coordinate (m) and velocity (m/s) along its axis (the y of a top or bottom
        piston, the x of a left or right one).
    work : float
        Energy it has given the gas since the start, J (negative when the gas pushed it out).
    """

    wall: str
    position: float
    velocity: float
    work: float

    def to_dict(self) -> dict[str, Any]:
        """Plain values, as in ``--json``."""
        return {"wall": self.wall, "position": self.position, "velocity": self.velocity,
                "work": self.work}  # fmt: skip


@dataclass(frozen=True)
class Counters:
    """Collision counts since the simulation was created."""

    pair_collisions: int
    wall_hits: dict[str, int]

    @property
    def wall_collisions(self) -> int:
        """Hits on all walls together."""
        return sum(self.wall_hits.values())


class Simulation:
    """Particles in a vessel, advanced by leapfrog with exact (or seed-style) collisions.

    Parameters
    ----------
    container : Vessel
        The vessel (`collidium.vessels`: a `Box`, a `Circle` or a `Polygon`).
    particles : Particles
        Initial state (the simulation keeps and updates this object).
    forces : sequence of Force, optional
        The forces acting (`collidium.forces`: `Coulomb`, `Newton`, `Gravity`, `UniformField`);
        none for a free (hard-disk) gas.
    dt : float
        Time step in s (> 0), the interval between reports. Without forces and with exact
        collisions the motion is exact whatever its value; with forces the adaptive integrator
        takes substeps inside it.
    collisions : {"exact", "step", "off"}
        Collision handling, see `collidium.collisions`.
    integrator : {"adaptive", "fixed"}
        Time stepping with forces, see `collidium.integrators`: "adaptive" substeps inside each dt
        as the forces need (energy error ~ ``tolerance^2``), "fixed" one leapfrog step of dt (the
        seed's scheme). The same without forces.
    tolerance : float
        The adaptive integrator's accuracy parameter (> 0): the largest substep as a fraction of
        the forces' fastest time scale, weighted by energy (`collidium.integrators`).
    restitution : float
        Normal restitution coefficient e of the pair collisions, in (0, 1]: 1 (the default) is
        elastic; below 1 the gas loses ``(1 - e^2)`` of each collision's normal kinetic energy
        (`collision_heat`), a granular gas (`collidium.kernels.collision.pair_response`).
    seed : int, optional
        Seed of the simulation's random generator (`rng`).
    name : str, optional
        Label used in summaries (the scenario or preset name).

    Raises
    ------
    InputError
        For a bad dt, mode, integrator or tolerance, disks too large for the vessel, overlapping
        disks (the pair is named) or a particle outside the vessel.
    """

    _integrator: Integrator

    def __init__(
        self,
        container: Vessel,
        particles: Particles,
        forces: Sequence[Force] = (),
        dt: float = 0.01,
        collisions: CollisionMode = "exact",
        seed: int | None = None,
        name: str | None = None,
        integrator: IntegratorName = "adaptive",
        tolerance: float = DEFAULT_TOLERANCE,
        restitution: float = 1.0,
    ) -> None:
        _check_setup(container, particles, forces, dt, collisions)
        _check_integrator(integrator, tolerance)
        check_restitution(restitution)
        if container.periodic:
            wrapped = container.wrap(particles.position)
            size = container.size
            particles.image += np.rint((particles.position - wrapped) / size).astype(np.int64)
            particles.position[...] = wrapped
        _check_placement(container, particles, collisions)
        self._setup(container, particles, forces, dt, collisions, seed, name, restitution)
        self._integrator = make_integrator(integrator, tolerance)

    def _setup(
        self,
        container: Vessel,
        particles: Particles,
        forces: Sequence[Force],
        dt: float,
        collisions: CollisionMode,
        seed: int | None,
        name: str | None,
        restitution: float = 1.0,
    ) -> None:
        self._container = container
        self.particles = particles
        self._dt = float(dt)
        self._time_origin = (0.0, 0)  # (time, steps) when dt was last set
        self._collisions: CollisionMode = collisions
        self.seed = seed
        self.rng = np.random.default_rng(seed)
        self.name = name or "custom"
        self.steps = 0
        self.observers: list[Observer] = []
        self._attached: list[Observer] = []  # observers already attached (by identity)
        self._restitution = float(restitution)
        self._drift = make_drift(collisions, self._restitution)
        self._field = self._make_field(forces)
        self._integrator = make_integrator("adaptive", DEFAULT_TOLERANCE)
        self.tally = Tally.for_vessel(container)

    @property
    def container(self) -> Vessel:
        """The vessel; may be replaced between runs by one with the same walls and other
        responses (`collidium.vessels.Vessel.with_walls`): walls held hot, a wall turned into a
        piston, a piston driven or let go.

        A piston on the wall that already was one keeps where it is and, unless the new one is
        driven (moved at its own velocity), how fast it moves; a new piston starts at its
        ``position`` and ``velocity``.

        Raises
        ------
        InputError
            If the walls differ, a particle would lie beyond the new piston, or the vessel does
            not suit the forces or the collision mode. Nothing changes then.
        """
        return self._container

    @container.setter
    def container(self, vessel: Vessel) -> None:
        _check_setup(vessel, self.particles, self.forces, self.dt, self.collisions)
        if vessel.wall_names != self._container.wall_names or type(vessel) is not type(
            self._container
        ):
            raise InputError(
                "container", f"must have the walls of the {self._container.describe()} "
                "(give them other responses); start a new simulation for another vessel"
            )  # fmt: skip
        piston = _carried_piston(self._container, vessel, self.tally.piston)
        _check_inside(vessel, self.particles, *piston[:1])  # walls move no disk onto another
        self._container, self.tally.piston = vessel, piston
        self._drift.forget()  # its queue holds the old piston

    @property
    def dt(self) -> float:
        """Time step in s; may be changed between runs."""
        return self._dt

    @dt.setter
    def dt(self, value: float) -> None:
        _check_dt(value)
        self._time_origin = (self.time, self.steps)
        self._dt = float(value)

    @property
    def time(self) -> float:
        """Simulated time in s: counted in whole steps, ``t0 + (steps - k0) * dt``, so that it
        carries no accumulated round-off."""
        t0, k0 = self._time_origin
        return t0 + (self.steps - k0) * self._dt

    @property
    def collisions(self) -> CollisionMode:
        """Collision mode: "exact", "step" or "off"; may be changed between runs.

        Disks that came to overlap while collisions were off separate again under "exact"
        (approaching overlapping pairs collide at once) and under "step".
        """
        return self._collisions

    @collisions.setter
    def collisions(self, mode: CollisionMode) -> None:
        _check_mode(mode, self.container)
        if mode != self._collisions:
            self._collisions = mode
            self._drift = make_drift(mode, self._restitution)
            self._field = self._make_field(self.forces)

    @property
    def restitution(self) -> float:
        """Normal restitution coefficient e of the pair collisions, in (0, 1] (1: elastic;
        below 1, a granular gas that cools); may be changed between runs."""
        return self._restitution

    @restitution.setter
    def restitution(self, value: float) -> None:
        check_restitution(value)
        if value != self._restitution:
            self._restitution = float(value)
            self._drift = make_drift(self._collisions, self._restitution)

    @property
    def integrator(self) -> IntegratorName:
        """Time stepping with forces: "adaptive" or "fixed"; may be changed between runs."""
        return self._integrator.name

    @integrator.setter
    def integrator(self, name: IntegratorName) -> None:
        _check_integrator(name, self.tolerance)
        if name != self._integrator.name:
            self._integrator = make_integrator(name, self.tolerance)

    @property
    def tolerance(self) -> float:
        """The adaptive integrator's accuracy parameter (kept, unused, by "fixed")."""
        return self._integrator.tolerance

    @tolerance.setter
    def tolerance(self, value: float) -> None:
        _check_integrator(self.integrator, value)
        self._integrator = make_integrator(self.integrator, value)

    @property
    def forces(self) -> tuple[Force, ...]:
        """The forces acting; may be replaced between runs (an empty sequence for none)."""
        return self._field.forces

    @forces.setter
    def forces(self, forces: Sequence[Force]) -> None:
        _check_forces(forces, self.container, self.particles)
        self._field = self._make_field(forces)

    def _make_field(self, forces: Sequence[Force]) -> ForceField:
        """The forces as the integrators step with them, a uniform gravity carried by the drift
        where it flies parabolas (`collidium.collisions.Drift.carries_fall`)."""
        return ForceField(tuple(forces), self.rng, self._drift.carries_fall)

    def add_particles(self, new: Particles) -> None:
        """Put ``new`` particles into the vessel, after the others (a pump, a source).

        Raises
        ------
        InputError
            If one lies outside the vessel (or beyond its piston) or overlaps another particle
            (unless collisions are off), naming it; or if observers are attached, whose records
            are per particle. Nothing changes then.
        """
        self._refuse_observers()
        joined = self.particles.joined(new)
        piston = self.piston()
        _check_placement(
            self.container, joined, self.collisions, None if piston is None else piston.position
        )
        self.particles = joined

    def remove_particles(self, indices: ArrayLike) -> None:
        """Take the particles at ``indices`` out of the vessel (a leak, a sink); the others keep
        their order.

        Raises
        ------
        InputError
            If an index is not a particle's, or observers are attached.
        """
        self._refuse_observers()
        chosen = np.asarray(indices, dtype=np.int64).reshape(-1)
        if chosen.size and (chosen.min() < 0 or chosen.max() >= self.particles.n):
            raise InputError("indices", f"must be particles 0 to {self.particles.n - 1}")
        self.particles = self.particles.without(chosen)

    def _refuse_observers(self) -> None:
        if self.observers:
            raise InputError(
                "particles", "observers are attached; their records are per particle: "
                "add or remove particles before attaching them"
            )  # fmt: skip

    def run(
        self, time: float | None = None, steps: int | None = None, progress: bool = False
    ) -> Simulation:
        """Advance by a duration or a number of steps.

        Parameters
        ----------
        time : float, optional
            Duration in s, rounded to a whole number of steps of ``dt``.
        steps : int, optional
            Number of steps (give one of ``time`` and ``steps``).
        progress : bool
            Show a rich progress bar on stderr.

        Returns
        -------
        Simulation
            ``self``, to chain calls.
        """
        count = step_count(time, steps, self.dt)
        for observer in self.observers:
            if not any(observer is seen for seen in self._attached):
                observer.attach(self)
                self._attached.append(observer)
        if self._field.kicks:
            self._field.refresh(self.particles, self.container)
        if progress:
            from rich.console import Console
            from rich.progress import Progress

            with Progress(console=Console(stderr=True), transient=True) as bar:
                task = bar.add_task(f"{self.name}", total=count)
                stride = max(1, count // 200)
                for done in range(0, count, stride):
                    self._advance(min(stride, count - done))
                    bar.update(task, completed=min(done + stride, count))
        else:
            self._advance(count)
        return self

    def _advance(self, count: int) -> None:
        """Take ``count`` steps: one compiled call for each run of steps the integrator can fly
        (`Integrator.fly`) before an observer reads the state, the others one by one."""
        done = 0
        untouched = False  # whether the particles are as the last step of this call left them
        while done < count:
            run = self._run_length(count - done)
            if run > 1:
                flown = self._fly(run)
                done += flown
                untouched = False
                if flown == run:
                    continue
            if untouched and not self._field.kicks:  # nothing but the drift moves them
                self._drift.vouch()
            untouched = not self._step()
            done += 1

    def _run_length(self, left: int) -> int:
        """Steps, up to ``left`` and `MOST_FLOWN`, until an observer reads the state: one unless
        the integrator can fly here and every trigger is `foreseeable`. Those that read no more
        than a flight records (``take_flown``, `collidium.observers.Flown`) do not count once
        they have started, unless the vessel has a piston (`_reads_state`)."""
        run = min(left, MOST_FLOWN)
        if not all(foreseeable(observer.trigger) for observer in self.observers):
            return 1
        readers = [o.trigger for o in self.observers if self._reads_state(o)]
        for trigger in readers:  # the cheap ones first
            if isinstance(trigger, Every):
                run = min(run, trigger.period - self.steps % trigger.period)
        if run <= 1 or not self._integrator.flies(
            self.particles, self.container, self._field, self._drift, self.tally
        ):
            return 1
        for trigger in readers:
            if not isinstance(trigger, Every):
                run = self._next_firing(trigger, run)
        return run

    def _next_firing(self, trigger: Trigger, within: int) -> int:
        """Steps from now to the next firing of a `foreseeable` ``trigger`` if it fires within
        ``within`` steps, else ``within``; looked for in windows eight times longer each, so
        that a trigger that fires soon costs little."""
        done, window = 0, 8
        while done < within:
            count = min(window, within) - done
            steps, times = self._steps_ahead(self.steps + done, count)
            fires = fires_at(trigger, steps, times, self.dt)
            if fires.any():
                return done + int(fires.argmax()) + 1
            done, window = done + count, 8 * window
        return within

    def _steps_ahead(self, first: int, count: int) -> tuple[IntArray, FloatArray]:
        """The ``count`` steps after step ``first`` and the times they end at (s), as `time`
        counts them."""
        origin, start = self._time_origin
        steps = np.arange(first + 1, first + count + 1)
        return steps, np.asarray(origin + (steps - start) * self.dt, dtype=np.float64)

    def _reads_state(self, observer: Observer) -> bool:
        """Whether ``observer`` reads more of the state than a flight records: it has no
        ``take_flown``, or it is a measurement yet to start its window (its first sample, under
        an `After` trigger, also reads what stays fixed over the window, and the energy it
        starts from), or the vessel has a piston (the record holds none, and the vessel changes
        as it moves: a flight then stops at every observer's firing)."""
        return (
            not _only_reads(observer)
            or not getattr(observer, "sampled", True)
            or self.tally.piston.size > 0
        )

    def _fly(self, run: int) -> int:
        """Up to ``run`` steps in one compiled call; the observers that read no more than its
        record get what they would have read on each step they fire on, and after the last
        step, if it was taken, the others fire as after any step. Returns the steps taken."""
        first = self.steps
        origin, start = self._time_origin
        steps, times = self._steps_ahead(first, run)
        readers = [observer for observer in self.observers if self._reads_state(observer)]
        takers = [(observer, fires_at(observer.trigger, steps, times, self.dt))
                  for observer in self.observers if not self._reads_state(observer)]  # fmt: skip
        wanted = np.zeros(run, dtype=bool)
        for _, fires in takers:
            wanted |= fires
        record = FlightRecord.empty(self.tally, wanted)
        flown = self._integrator.fly(
            self.particles, self.container, self._field, self._drift, origin, first - start,
            self.dt, self.tally, record,
        )  # fmt: skip
        if flown == 0:
            return 0
        self.steps += flown
        # As `_step`: the observers fire after each step that passed the audit. A flight ends at
        # the first step that fails it.
        self._take_flown(takers, times, record, 0, flown - 1)
        self._audit()
        self._take_flown(takers, times, record, flown - 1, flown)
        if flown == run:
            for observer in readers:
                if observer.trigger(self):
                    observer.update(self)
        return flown

    def _take_flown(
        self,
        takers: list[tuple[Observer, BoolArray]],
        times: FloatArray,
        record: FlightRecord,
        first: int,
        stop: int,
    ) -> None:
        """Hand the observers that take a flight's record (``takers``, with ``take_flown``, and
        the steps each fires on) the record's rows ``first`` to ``stop - 1`` of the steps that
        end at ``times`` (s), at those they fire on."""
        rows = slice(first, stop)
        for observer, fires in takers:
            at = fires[rows]
            if at.any():
                kinetic, potential, virial, px, py, speed = record.values[rows][at].T
                flown = Flown(times[rows][at], kinetic, potential, virial, px, py, speed,
                              record.counts[rows][at], record.impulse[rows][at],
                              record.heat[rows][at], record.forces[rows][at])  # fmt: skip
                take = getattr(observer, "take_flown")  # noqa: B009 (not in the protocol)
                take(self, flown)

    def _step(self) -> bool:
        """One step, its audit and its observers; returns whether an observer fired that may
        have changed the particles (one that does not only read: `_only_reads`)."""
        try:
            self._integrator.step(
                self.particles, self.container, self._field, self._drift, self.time, self.dt,
                self.tally,
            )  # fmt: skip
        except SimulationError as exc:
            raise SimulationError(f"step {self.steps + 1} (t = {self.time:.6g} s): {exc}") from None
        self.steps += 1
        self._audit()
        touched = False
        for observer in self.observers:
            if observer.trigger(self):
                observer.update(self)
                touched |= not _only_reads(observer)
        return touched

    def _audit(self) -> None:
        p = self.particles
        vessel = self.container
        index, reason = first_invalid(
            p.position, p.velocity, p.radius, *vessel.audit_arguments(), vessel.segments(),
        )  # fmt: skip
        if index < 0 and self._past_piston():
            reason = 2
        elif index < 0:
            return
        what = "a non-finite position or velocity" if reason == 1 else "left the vessel"
        if reason == 1:
            bad = np.flatnonzero(~np.isfinite(p.position).all(1) | ~np.isfinite(p.velocity).all(1))
        else:
            bad = vessel.outside(p.position, p.radius, *self.tally.piston[:1])
        listed = ", ".join(str(int(i)) for i in bad[:10]) + (" ..." if bad.size > 10 else "")
        raise SimulationError(
            f"step {self.steps} (t = {self.time:.6g} s): particle(s) {listed} {what}"
            + ("; try a smaller dt or softening" if reason == 1 else "")
        )

    def _past_piston(self) -> bool:
        """Whether a disk reaches past the piston's face where it is now (compiled: the rest of
        the audit is, and `escaped` took half a 200-disk step)."""
        if not self.tally.piston.size:
            return False
        face = self.container.piston_face(float(self.tally.piston[0]))
        p = self.particles
        return face is not None and first_past_face(p.position, p.radius, *face) >= 0

    def energy(self) -> Energy:
        """Kinetic (``sum m v^2 / 2``) and potential (pair sum, seed eq. 10) energy in J."""
        return Energy(self._kinetic(), self._field.potential(self.particles, self.container))

    def _kinetic(self) -> float:
        # In particle order, as the compiled intervals sum it (`collidium.kernels.sums`).
        return float(sums.kinetic_energy(writable(self.particles.mass), self.particles.velocity))

    def temperature(self) -> float:
        """kT = KE / N in J (2 degrees of freedom per particle, Boltzmann's constant 1); NaN
        for an empty vessel.

        The centre-of-mass motion is included: with walls momentum is not conserved and it is
        part of the thermal motion; in a periodic box, where momentum is conserved, the
        equipartition value ``(KE - P^2 / 2M) / (N - 1)`` differs from it by order 1/N.
        """
        n = self.particles.n
        return self._kinetic() / n if n else float("nan")  # no pair sum: it is O(N^2)

    def virial(self) -> float:
        """Pair virial of the forces, ``sum_{i<j} r_ij . F_ij``, in J at the current positions
        (0 without forces; collisions add theirs through ``tally.impulse``)."""
        return self._field.virial(self.particles, self.container)

    def momentum(self) -> FloatArray:
        """Total momentum ``sum m v``, shape (2,), in kg m/s."""
        return np.array(sums.momentum(writable(self.particles.mass), self.particles.velocity))

    def angular_momentum(self) -> float:
        """Total angular momentum about the origin, ``sum m (x v_y - y v_x)``, kg m^2/s: conserved
        in a circle (about its centre), not by the flat walls of a box."""
        p = self.particles
        x, v = p.position, p.velocity
        return float(np.sum(p.mass * (x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0])))

    def total_speed(self) -> float:
        """Sum of the particles' speeds in m/s (the seed's "total speed", Fig. 2)."""
        return float(sums.total_speed(self.particles.velocity))

    @property
    def counters(self) -> Counters:
        """Pair collisions and wall hits (per wall) since the start."""
        names = self.container.wall_names
        hits = {name: int(self.tally.counts[1 + k]) for k, name in enumerate(names)}
        return Counters(int(self.tally.counts[0]), hits)

    def wall_heat(self) -> dict[str, float]:
        """Energy each wall has given the disks since the start, J, by wall name (negative when
        it took energy; 0 for mirrors)."""
        names = self.container.wall_names
        return {name: float(self.tally.heat[1 + k]) for k, name in enumerate(names)}

    def collision_heat(self) -> float:
        """Energy inelastic pair collisions have given the disks since the start, J (negative:
        what they took; 0 when elastic)."""
        return float(self.tally.heat[0])

    def force_heat(self) -> float:
        """Energy the velocity forces (drag, friction, a thermostat) have given the disks since
        the start, J (negative: the heat they took; 0 for a magnetic field)."""
        return float(self.tally.forces[0])

    def escaped(self) -> int:
        """Number of particles outside the vessel (always 0 unless something is badly wrong)."""
        p = self.particles
        return int(self.container.outside(p.position, p.radius, *self.tally.piston[:1]).size)

    def piston(self) -> PistonState | None:
        """Where the vessel's piston is, how fast it moves and the work it has done on the gas;
        None without a piston (`collidium.vessels.walls.Piston`)."""
        if self.container.piston is None:
            return None
        wall = self.container.piston[0]
        position, velocity = (float(x) for x in self.tally.piston)
        return PistonState(
            self.container.wall_names[wall], position, velocity, float(self.tally.heat[1 + wall])
        )

    def unwrapped_position(self) -> FloatArray:
        """Positions (N, 2) in m with periodic wrapping undone (equal to position otherwise)."""
        return self.particles.position + self.particles.image * self.container.size

    def summary(self) -> dict[str, Any]:
        """Plain numbers describing the current state (used by the CLI)."""
        e = self.energy()
        c = self.counters
        out = {
            "scenario": self.name,
            "n": self.particles.n,
            "time": self.time,
            "steps": self.steps,
            "energy": {"kinetic": e.kinetic, "potential": e.potential, "total": e.total},
            "momentum": [float(x) for x in self.momentum()],
            "angular_momentum": self.angular_momentum(),
            "total_speed": self.total_speed(),
            "collisions": {"pair": c.pair_collisions, "wall": c.wall_collisions},
            "wall_heat": self.wall_heat(),
            "collision_heat": self.collision_heat(),
            "force_heat": self.force_heat(),
            "escaped": self.escaped(),
        }
        piston = self.piston()
        if piston is not None:
            out["piston"] = piston.to_dict()
        return out

    def save(self, path: str | Path, **meta: Any) -> None:
        """Write a checkpoint from which `restore` continues bit for bit.

        The state, the counters, the random generator and the collision engine's queue are saved;
        observers are not. ``meta`` (JSON-serialisable) is stored alongside, for front ends.
        The file is replaced atomically.
        """
        p = self.particles
        # A value all particles share is saved once, and comes back shared.
        properties = {name: np.asarray(as_given(getattr(p, name))) for name in PROPERTIES}
        drift = {f"drift/{key}": value for key, value in self._drift.state().items()}
        integrator = {f"integrator/{k}": v for k, v in self._integrator.state().items()}
        arrays = {
            "position": p.position, "velocity": p.velocity, "image": p.image,
            "tally/counts": self.tally.counts, "tally/impulse": self.tally.impulse,
            "tally/heat": self.tally.heat, "tally/piston": self.tally.piston,
            "tally/forces": self.tally.forces,
        } | properties | drift | integrator  # fmt: skip
        state = {
            "name": self.name,
            "vessel": self.container.to_dict(),
            "forces": [force.to_dict() for force in self.forces],
            "dt": self._dt,
            "time_origin": list(self._time_origin),
            "steps": self.steps,
            "collisions": self.collisions,
            "restitution": self.restitution,
            "integrator": self.integrator,
            "tolerance": self.tolerance,
            "seed": self.seed,
            "rng": self.rng.bit_generator.state,
        }
        write_checkpoint(path, arrays, {"simulation": state, "extra": meta})

    def copy(self) -> Simulation:
        """An independent copy (state, counters, engine queue, random generator), without the
        observers; it continues exactly as this simulation would."""
        observers, attached = self.observers, self._attached
        self.observers, self._attached = [], []
        try:
            return copy.deepcopy(self)
        finally:
            self.observers, self._attached = observers, attached

    def __repr__(self) -> str:
        return (
            f"Simulation({self.name!r}, n={self.particles.n}, {self.container!r}, "
            f"collisions={self.collisions!r}, dt={self.dt}, time={self.time:.6g})"
        )


def restore(path: str | Path) -> Simulation:
    """The simulation saved by `Simulation.save`, ready to continue bit for bit.

    Raises
    ------
    InputError
        If the file is missing, damaged or not a collidium checkpoint.
    """
    sim, _ = restore_with_meta(path)
    return sim


def restore_with_meta(path: str | Path) -> tuple[Simulation, dict[str, Any]]:
    """`restore`, also returning the ``meta`` given to `Simulation.save`."""
    arrays, meta = read_checkpoint(path)
    try:
        state = meta["simulation"]
        particles = Particles(
            arrays["position"], arrays["velocity"], mass=arrays["mass"],
            radius=arrays["radius"], charge=arrays["charge"], image=arrays["image"],
        )  # fmt: skip
        forces = [force_from_dict(f, f"forces.{k}") for k, f in enumerate(state["forces"])]
        vessel = vessel_from_dict(saved_vessel(state))
        container = _check_setup(vessel, particles, forces, state["dt"], state["collisions"])
        sim = Simulation.__new__(Simulation)
        # The saved state may hold contacts at round-off distance (or the step method's
        # overlaps): it is taken as saved, without the placement checks of a new simulation.
        sim._setup(container, particles, forces, state["dt"], state["collisions"], state["seed"],
                   state["name"], state.get("restitution", 1.0))  # fmt: skip
        # Checkpoints from before the adaptive integrator continue with the step they were made by.
        integrator, tolerance = state.get("integrator", "fixed"), state.get("tolerance")
        tolerance = DEFAULT_TOLERANCE if tolerance is None else tolerance
        _check_integrator(integrator, tolerance)
        sim._integrator = make_integrator(integrator, tolerance)
        sim._integrator.load_state(
            {k.removeprefix("integrator/"): v for k, v in arrays.items()
             if k.startswith("integrator/")}
        )  # fmt: skip
        sim._time_origin = (float(state["time_origin"][0]), int(state["time_origin"][1]))
        sim.steps = int(state["steps"])
        sim.rng.bit_generator.state = state["rng"]
        # Tallies of checkpoints made before vessels had their own number of walls held five
        # entries, the walls' first.
        for name in ("counts", "impulse", "heat", "piston", "forces"):
            if f"tally/{name}" in arrays:  # absent from those made before thermal walls, forces
                tally = getattr(sim.tally, name)
                tally[...] = arrays[f"tally/{name}"][: tally.size]
        sim._drift.load_state(
            {k.removeprefix("drift/"): v for k, v in arrays.items() if k.startswith("drift/")}
        )
    except InputError as exc:
        raise InputError(
            str(path), f"checkpoint holds an invalid {exc.field}: {exc.reason}"
        ) from None
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise InputError(str(path), f"checkpoint is incomplete or damaged ({exc!r})") from None
    return sim, meta.get("extra", {})


def step_count(time: float | None, steps: int | None, dt: float) -> int:
    """Steps of ``dt`` in ``time`` (rounded), or ``steps`` checked; exactly one is given."""
    if (time is None) == (steps is None):
        raise InputError("time", "give exactly one of time and steps")
    if steps is not None:
        if isinstance(steps, bool) or int(steps) != steps or not 0 <= steps <= MAX_STEPS:
            raise InputError(
                "steps", f"must be a whole number in [0, {MAX_STEPS:.0e}], got {steps!r}"
            )
        return int(steps)
    assert time is not None
    if not math.isfinite(time) or time < 0:
        raise InputError("time", f"must be a finite number >= 0, got {time!r}")
    count = time / dt
    if count > MAX_STEPS:
        raise InputError(
            "time", f"{time:g} s is {count:.3g} steps of {dt:g} s; at most {MAX_STEPS:.0e}"
        )
    return round(count)


def _check_setup(
    container: Vessel,
    particles: Particles,
    forces: Sequence[Force],
    dt: float,
    collisions: str,
) -> Vessel:
    """Refuse a bad setup (one line naming the field); returns the vessel."""
    if not isinstance(container, Vessel):
        raise InputError(
            "container", f"must be a vessel (Box, Circle), got {type(container).__name__}"
        )
    if not isinstance(particles, Particles):
        raise InputError("particles", f"must be Particles, got {type(particles).__name__}")
    _check_forces(forces, container, particles)
    _check_dt(dt)
    _check_mode(collisions, container)
    container.check_fits(particles.radius)
    _check_kinetic_energy(particles)
    return container


def _check_kinetic_energy(particles: Particles) -> None:
    """Refuse speeds whose kinetic energy is beyond float64 (every later sum would overflow)."""
    with np.errstate(over="ignore", invalid="ignore"):
        energy = particles.mass * np.einsum("ij,ij->i", particles.velocity, particles.velocity)
        total = float(np.sum(energy))
    if not math.isfinite(total):
        fastest = float(np.abs(particles.velocity).max(initial=0.0))
        heaviest = float(particles.mass.max(initial=0.0))
        raise InputError("particles.velocity", f"the kinetic energy overflows float64 (a velocity "
                                               f"component of {fastest:.3g} m/s, masses up to "
                                               f"{heaviest:.3g} kg)")  # fmt: skip


def _check_forces(forces: Sequence[Force], container: Vessel, particles: Particles) -> None:
    if container.piston is not None and not all(_falls(force) for force in forces):
        # The exact engine flies a uniform gravity; anything else would kick the gas while
        # the piston moves on.
        raise InputError(
            "forces", "a vessel with a piston holds a gas without forces, or under gravity only"
        )
    for k, force in enumerate(forces):
        if not isinstance(force, Force):
            raise InputError(f"forces.{k}", f"not a force: {type(force).__name__}")
        force.check(particles, container)


def _falls(force: object) -> bool:
    """Whether a force is a uniform gravity, the same acceleration for every particle."""
    return isinstance(force, PositionForce) and force.fall is not None


def _check_integrator(integrator: str, tolerance: float) -> None:
    if integrator not in INTEGRATORS:
        raise InputError("integrator", f"must be one of {INTEGRATORS}, got {integrator!r}")
    if (
        isinstance(tolerance, bool)
        or not isinstance(tolerance, int | float)
        or not math.isfinite(tolerance)
        or tolerance <= 0
    ):
        raise InputError("tolerance", f"must be a finite number > 0, got {tolerance!r}")


def _check_mode(collisions: str, container: Vessel) -> None:
    if collisions not in COLLISION_MODES:
        raise InputError("collisions", f"must be one of {COLLISION_MODES}, got {collisions!r}")
    if collisions != "exact" and container.piston is not None:
        raise InputError("collisions", "a piston moves in the exact engine only: use 'exact'")


def _check_dt(dt: float) -> None:
    if isinstance(dt, bool) or not isinstance(dt, int | float) or not math.isfinite(dt) or dt <= 0:
        raise InputError("dt", f"must be a finite number > 0, got {dt!r}")


def outside_detail(container: Vessel, particles: Particles, i: int) -> str:
    """Where particle i is and why that is outside the vessel (for error messages)."""
    x, y = particles.position[i]
    radius = particles.radius[i]
    return f"at ({x:g}, {y:g}) with radius {radius:g} is outside the {container.describe()}"


def overlap_detail(container: Vessel, particles: Particles, i: int, j: int) -> str:
    """How far apart two overlapping disks are (for error messages)."""
    gap = np.linalg.norm(container.minimum_image(particles.position[j] - particles.position[i]))
    radius = particles.radius
    return f"(centres {gap:g} m apart, radii {radius[i]:g} + {radius[j]:g})"


def _carried_piston(old: Vessel, new: Vessel, state: FloatArray) -> FloatArray:
    """`collidium.collisions.Tally.piston` for ``new`` replacing ``old`` whose piston is at
    ``state`` (position, velocity) (see `Simulation.container`)."""
    if new.piston is None:
        return np.empty(0)
    wall, piston = new.piston
    if old.piston is None or old.piston[0] != wall:
        return np.array([piston.position, piston.velocity], dtype=float)
    if piston.driven and piston.stop is not None:
        ahead = (piston.stop - state[0]) * piston.velocity
        if ahead < 0:
            raise InputError(
                f"walls.{new.wall_names[wall]}.stop", f"is behind the piston's face, at "
                f"{state[0]:.6g} m now: it must lie ahead of the piston's motion"
            )  # fmt: skip
    return np.array([state[0], piston.velocity if piston.driven else state[1]], dtype=float)


def _check_inside(container: Vessel, particles: Particles, piston_at: float | None = None) -> None:
    outside = container.outside(particles.position, particles.radius, piston_at)
    if outside.size:
        i = int(outside[0])
        detail = outside_detail(container, particles, i)
        raise InputError("position", f"particle {i} {detail}", particles=(i,))


def _check_placement(
    container: Vessel, particles: Particles, collisions: str, piston_at: float | None = None
) -> None:
    _check_inside(container, particles, piston_at)
    if collisions == "off":
        return  # pass-through disks may overlap
    width, height = (float(side) for side in container.size)
    diameter = 2.0 * float(particles.radius.max(initial=0.0))
    window = grid_window(particles.position, diameter, (width, height), container.periodic)
    ncx, ncy = grid_shape(*window_sides(window), diameter, particles.n)
    i, j = first_overlap(
        particles.position, particles.radius, width, height, container.periodic, window, ncx, ncy
    )
    if i >= 0:
        detail = overlap_detail(container, particles, i, j)
        raise InputError("position", f"particles {i} and {j} overlap {detail}", particles=(i, j))


def _only_reads(observer: Observer) -> bool:
    """Whether ``observer`` only reads the state: one with ``take_flown``, which a flight
    passes by and hands what it would have read (the `Observer` protocol). Others may write."""
    return hasattr(observer, "take_flown")
