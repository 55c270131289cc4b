"""Time stepping: kick-drift-kick leapfrog (seed eq. 1-3), the drift done by the collision mode.

Two integrators advance the state over one reporting interval ``dt``:

- `AdaptiveLeapfrog` (``"adaptive"``, the default): as many substeps inside ``dt`` as the forces
  need, the contacts inside their drifts with the kick timing corrected to second order
  (`collidium.kernels.kick_timing`), the state shown processed
  (`collidium.kernels.processing`);
- `Leapfrog` (``"fixed"``): one kick-drift-kick step of ``dt``, the seed's scheme, kept to
  reproduce its results (energy error O(dt^2), and O(dt^2) per collision under forces).

Forces of the velocities (a magnetic field, drag, friction, a thermostat:
`collidium.forces.base.VelocityForce`) act by their exact flow for half a substep before each
kick-drift-kick and half after, a time-symmetric (Strang) splitting: a magnetic field turns
velocities without changing speeds, and the energy drag or a thermostat gives the particles is
kept in ``Tally.forces``.

Without forces both are the same single drift: the exact engine is then untouched. So is it
under a uniform gravity alone, whose parabolas it flies exactly (`ForceField.fall`).
"""

from __future__ import annotations

import math
import typing
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Literal

import numpy as np

from collidium.collisions import (
    ContactLog,
    Drift,
    ExactCollisions,
    FlightRecord,
    SubstepEngine,
    Tally,
)
from collidium.errors import SimulationError
from collidium.forces import ForceField
from collidium.forces.base import CompiledForces, Evaluation
from collidium.kernels import kick_timing, modified_energy, processing, substeps, sums
from collidium.kernels.pairwise import PARALLEL_DIRECT_FROM
from collidium.state import FloatArray, Particles, writable
from collidium.vessels import Vessel

IntegratorName = Literal["adaptive", "fixed"]
INTEGRATORS: tuple[IntegratorName, ...] = ("adaptive", "fixed")

#: The adaptive integrator's default accuracy parameter: the largest substep as a fraction of the
#: fastest pair time scale. It keeps every seed scene's energy error within a third of the
#: documented targets at dt = 0.01 s (README), the state shown processed; the energy error
#: scales as its square.
DEFAULT_TOLERANCE = 0.003

#: Most regular substeps in one reporting interval (a power of two). An interval that needs more
#: at its start stops the run with one line (the forces are too strong for this dt, and it would
#: take minutes); one that finds out only as it goes is taken with this many, and the energy
#: check of the run reports the error. The seed's point charges passing through each other
#: (charged-no-collisions) take up to 2^13 substeps a dt at the default tolerance and 2^17 at a
#: sixteenth of it: this leaves room for that, twice over.
MAX_SUBSTEPS = 2**18

#: The energy scale of the substep criterion is the total energy, but at least ``KE + |U|``
#: divided by this.
TOTAL_ENERGY_FLOOR = 10.0


class Integrator:
    """Advances the state over one reporting interval: the common part of the integrators.

    Without forces, or with only a uniform gravity that the drift carries, every integrator is
    the same single drift (the exact engine's queue then survives from step to step); with
    forces that kick `step` hands over to `_with_forces`.

    Parameters
    ----------
    tolerance : float
        The adaptive integrator's accuracy parameter; the fixed step keeps it, unused, so that
        switching back restores it.
    """

    name: IntegratorName

    def __init__(self, tolerance: float = DEFAULT_TOLERANCE) -> None:
        self.tolerance = float(tolerance)

    def step(
        self,
        particles: Particles,
        vessel: Vessel,
        field: ForceField,
        drift: Drift,
        now: float,
        dt: float,
        tally: Tally,
    ) -> None:
        """Advance ``particles`` in place from time ``now`` by ``dt`` (s), adding to ``tally``.

        The acceleration of the current positions must be in the field's cache: `ForceField`
        evaluates it once before the first step, and the integrator keeps it current.
        """
        if field.kicks:
            self._with_forces(particles, vessel, field, drift, now, dt, tally)
        else:
            drift.drift(particles, vessel, now, dt, tally, fall=field.fall)

    def _with_forces(
        self,
        particles: Particles,
        vessel: Vessel,
        field: ForceField,
        drift: Drift,
        now: float,
        dt: float,
        tally: Tally,
    ) -> None:
        raise NotImplementedError

    def flies(
        self, particles: Particles, vessel: Vessel, field: ForceField, drift: Drift, tally: Tally
    ) -> bool:
        """Whether `fly` may take steps here: without forces, or under a uniform gravity alone
        that the drift carries (`ForceField.falls_alone`), where the drift mode flies
        (`Drift.flies`); with forces that kick, where the integrator does
        (`_flies_with_forces`)."""
        if field.kicks:
            return self._flies_with_forces(particles, vessel, field, drift)
        return (not field.active or field.falls_alone) and drift.flies(
            particles, vessel, tally, field.fall
        )

    def fly(
        self,
        particles: Particles,
        vessel: Vessel,
        field: ForceField,
        drift: Drift,
        origin: float,
        elapsed: int,
        dt: float,
        tally: Tally,
        record: FlightRecord,
    ) -> int:
        """Take up to ``len(record.values)`` steps of ``dt`` (s) in one compiled call, as `step`
        would take them one by one, bit for bit, up to the first that this call cannot take
        (which is left as it began); returns how many it took.

        Parameters
        ----------
        particles, vessel, field, drift, tally
            As in `step`.
        origin : float
            The simulation's clock origin, s: step k starts at ``origin + (elapsed + k) dt``.
        elapsed : int
            Steps from the clock's origin to the first step's start.
        dt : float
            The reporting interval, s.
        record : FlightRecord
            Output: what the observers read at the end of each step taken.
        """
        if field.kicks:
            return self._fly_with_forces(particles, vessel, field, drift, origin, elapsed, dt,
                                         tally, record)  # fmt: skip
        if field.active and not field.falls_alone:  # the record has no other potential
            return 0
        taken = drift.fly(particles, vessel, origin, elapsed, dt, tally, record, field.fall)
        record.forces[:taken] = tally.forces[0]  # no velocity force gave any
        return taken

    def _flies_with_forces(
        self, particles: Particles, vessel: Vessel, field: ForceField, drift: Drift
    ) -> bool:
        """Whether `_fly_with_forces` may take steps here (none by default)."""
        return False

    def _fly_with_forces(
        self,
        particles: Particles,
        vessel: Vessel,
        field: ForceField,
        drift: Drift,
        origin: float,
        elapsed: int,
        dt: float,
        tally: Tally,
        record: FlightRecord,
    ) -> int:
        """`fly` under forces that kick (no steps by default)."""
        return 0

    def state(self) -> dict[str, np.ndarray]:
        """Arrays a checkpoint needs to continue bit for bit (none by default)."""
        return {}

    def load_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Take back what `state` returned."""


def make_integrator(name: IntegratorName, tolerance: float) -> Integrator:
    """The integrator of a name, with its tolerance (kept, unused, by ``"fixed"``)."""
    return (AdaptiveLeapfrog if name == "adaptive" else Leapfrog)(tolerance)


class Leapfrog(Integrator):
    """Velocity Verlet in kick-drift-kick form, one step of the reporting interval.

    ``v += a dt/2``; drift for dt (free flight with collisions, exact or not); ``a = F(x)/m``;
    ``v += a dt/2``. With exact collisions this is a Strang splitting of the hard-disk flow and the
    soft forces: collisions conserve energy exactly, the soft forces have a bounded O(dt^2) error,
    and each collision under a force adds an O(dt^2) error (the kicks are applied at the step's
    ends, not at the collision).
    """

    name: IntegratorName = "fixed"

    def _with_forces(
        self,
        particles: Particles,
        vessel: Vessel,
        field: ForceField,
        drift: Drift,
        now: float,
        dt: float,
        tally: Tally,
    ) -> None:
        _kick(particles, vessel, field, dt, tally)
        drift.drift(particles, vessel, now, dt, tally, field.acceleration, fall=field.fall)
        _closing_kick(particles, vessel, field, dt, tally, closes_step=True)


class AdaptiveLeapfrog(Integrator):
    """Kick-drift-kick with adaptive substeps inside the reporting interval.

    The interval ``dt`` is cut into ``n`` equal substeps, ``n`` a power of two, the smallest with
    ``dt / n <= tolerance * tau`` at every substep boundary of the interval. ``tau`` is the time
    scale of the forces weighted by energy: ``1 / tau^2 = max_ij |U_ij| rate_ij^2 / |E|``, with
    ``rate_ij`` a pair's fly-by and free-fall rate (`ForceField.stiffness`) and ``E`` the total
    energy (at least a tenth of ``KE + |U|``): a substep then errs on the energy by about
    ``tolerance^2`` of it, a lone pair in a close approach counting in full and a close pair of a
    gas by its share of the gas's energy. An interval
    that turns out to need more substeps than it was given is taken again from its start with
    more; the next interval starts from the same count, or half of it when half would have done.
    Substeps are equal within an interval and the check covers both ends of each, so no substep
    is sized from its start alone, which makes adaptive leapfrog drift: the scheme is
    time-symmetric within an interval, and the count of an interval depends on its neighbours
    only by that factor of two. The energy error stays bounded and scales as ``tolerance^2``.
    Where the substep changes from one interval to the next, the velocities are scaled so that
    the substeps' modified energy goes on (`collidium.kernels.modified_energy`; where the
    forces have one, `ForceField.keeps_modified_energy`): left, each change would leave its
    jump in the energy.

    Where those forces act between fixed walls (`shows`), the particles show not the
    integrator's own state but the processed one (`collidium.kernels.processing`): shifted, to
    first order, along the flow of ``sum v . F`` for ``h^2 / 12``, which takes the curvature's
    share out of the energy's swing about the modified energy (at the default tolerance the
    seed's charged scenes err 1.1 to 26 times less than the integrator's own state). The
    integrator keeps its own state behind it (`_Shown`, in the checkpoint too) and goes on
    from it while the particles hold what it showed, and from the inverse processing of
    whatever they hold after an edit.

    A contact under a force (a collision or a wall hit of a particle with an acceleration) falls
    inside a drift, between the kicks, which put the forces' impulse at the substep's ends. The
    engine's response takes out the first-order error of that timing, and once the forces at
    the substep's end are known the second-order part is corrected too
    (`collidium.kernels.kick_timing`): a contact costs no force evaluation of its own, and in a
    charged gas its error stays below that of the smooth substeps around it. This correction is
    the one part of the scheme that is not time-symmetric: it is exact for accelerations that
    change linearly before and after the contact, and its error is O(h^3) per contact. Where
    the pair forces are summed as their laws' gradients, each contact also gives back its jump
    of the substeps' modified energy, which the substeps between contacts keep: the energy then
    oscillates about it rather than random-walking from contact to contact.

    In a small scene under the forces the compiled substeps take (`_SmoothFlight`), an interval
    that meets no contact is taken whole by one compiled call
    (`collidium.kernels.substeps.smooth_intervals`), and `fly` takes many such intervals by the
    same call: the simulation flies the steps between the observers that read its state, bit
    for bit as `step` takes them one by one.

    Parameters
    ----------
    tolerance : float
        Largest substep as a fraction of the fastest time scale (> 0); energy error ~ its square.
    """

    name: IntegratorName = "adaptive"

    def __init__(self, tolerance: float = DEFAULT_TOLERANCE) -> None:
        super().__init__(tolerance)
        #: Regular substeps the next interval starts with (it may take more).
        self.substeps = 1
        #: The last interval's substep, s (NaN before the first).
        self.substep = math.nan
        self._flight: _SmoothFlight | None = None
        #: Whether `step` takes the next interval in Python at once, not tried whole: the last
        #: met a contact under forces (in a gas the next likely meets one too, and a try would
        #: cost its substeps up to the contact twice), or `fly` found that it meets one.
        self.next_in_python = False
        self._log = ContactLog()
        #: The record of a single interval compiled whole by `step`, not read but for the drag's
        #: heat (made again for a vessel of another number of walls).
        self._one: FlightRecord | None = None
        #: The integrator's own state behind the processed one the particles show, if it shows
        #: one (`_processed`).
        self._shown: _Shown | None = None

    def state(self) -> dict[str, np.ndarray]:
        """The substep count the next interval starts with, whether it is taken in Python at
        once, the last interval's substep, and the integrator's own state behind the one shown
        (`_Shown`), if any."""
        out = {
            "substeps": np.array([self.substeps], dtype=np.int64),
            "next_in_python": np.array([self.next_in_python]),
            "substep": np.array([self.substep]),
        }
        if self._shown is not None:
            out["shown"] = self._shown.stacked()
        return out

    def load_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Take back what `state` returned (a missing count starts at 1, a missing substep is
        none, a missing own state is found again from the state shown)."""
        self.substeps = int(arrays["substeps"][0]) if "substeps" in arrays else 1
        python = arrays.get("next_in_python")
        self.next_in_python = False if python is None else bool(python[0])
        self.substep = float(arrays["substep"][0]) if "substep" in arrays else math.nan
        shown = arrays.get("shown")
        self._shown = None if shown is None else _Shown.unstacked(shown)

    @contextmanager
    def _processed(
        self, particles: Particles, vessel: Vessel, field: ForceField, dt: float
    ) -> Iterator[None]:
        """Advance the integrator's own state and show the processed one
        (`collidium.kernels.processing`), where the forces' modified energy is known and the
        vessel has fixed walls (`shows`): the particles hold the state shown between steps, the
        integrator its own. A run that stops with an error leaves the particles as they were."""
        if not shows(particles, vessel, field):
            self._shown = None
            yield
            return
        if self._shown is None or not self._shown.matches(particles, vessel, field):
            if math.isnan(self.substep):  # the substep that the first interval starts from
                self.substep = dt / self.needed(self._start_rate(particles, vessel, field), dt)
            self._shown = _Shown.behind(particles, vessel, field, self.substep)
        before = self._shown
        before.resume(particles, vessel, field)
        try:
            yield
        except BaseException:
            particles.position[...] = before.shown_position
            particles.velocity[...] = before.shown_velocity
            raise
        self._shown = _Shown.show(particles, vessel, field, self.substep, before.made_with)

    def _start_rate(self, particles: Particles, vessel: Vessel, field: ForceField) -> float:
        """`_squared_rate` of the particles as they are (1/s^2)."""
        field.refresh(particles, vessel)
        return _squared_rate(particles, vessel, field, _total(particles, vessel, field))

    def needed(self, rate2: float, dt: float) -> int:
        """The fewest substeps, a power of two up to `MAX_SUBSTEPS`, that keep ``dt / n`` within
        ``tolerance`` times the time scale ``1 / sqrt(rate2)`` (``rate2`` in 1/s^2)."""
        return int(substeps.needed(rate2, dt, self.tolerance, MAX_SUBSTEPS))

    def _with_forces(
        self,
        particles: Particles,
        vessel: Vessel,
        field: ForceField,
        drift: Drift,
        now: float,
        dt: float,
        tally: Tally,
    ) -> None:
        with self._processed(particles, vessel, field, dt):  # on the integrator's own state
            flight = self._flight_for(particles, vessel, field, drift)
            tried = flight is not None and not self.next_in_python
            if tried and self._intervals(typing.cast(_SmoothFlight, flight), particles, field, now,
                                         0, dt, tally, self._one_record(tally)):  # fmt: skip
                return  # compiled whole
            start = _Snapshot(particles, tally)
            # The energy the substeps' rate is judged against: the interval's one read of the
            # energies (the forces keep the total within the tolerance over the interval).
            total = _total(particles, vessel, field)
            evaluated = field.saved()  # put back with the particles: no evaluation to take it again
            rate2 = (
                _squared_rate(particles, vessel, field, total)
                if flight is None
                else flight.squared_rate(particles, field, tally, total)
            )
            if not dt * math.sqrt(rate2) <= MAX_SUBSTEPS * self.tolerance:  # also NaN
                raise SimulationError(
                    f"the forces need more than {MAX_SUBSTEPS} substeps in one dt = {dt:g} s at "
                    f"t = {now:.6g} s: they are too strong for this dt; try a smaller dt, a larger "
                    "softening or a larger tolerance"
                )
            n = max(self.substeps, self.needed(rate2, dt))
            keep = field.keeps_modified_energy(particles, vessel)
            while True:
                if keep and not math.isnan(self.substep) and dt / n != self.substep:
                    _keep_modified_energy(particles, vessel, field, self.substep, dt / n,
                                          self.tolerance)  # fmt: skip
                try:
                    fastest, self.next_in_python = self._interval(
                        particles, vessel, field, drift, flight, now, dt, tally, n, rate2, total
                    )
                except SimulationError:  # a stop inside leaves the state it began from
                    start.restore(particles, tally)
                    field.restore(evaluated)
                    raise
                required = self.needed(fastest, dt)
                if required <= n:
                    break
                start.restore(particles, tally)
                field.restore(evaluated)
                n = max(required, 2 * n)
            self.substeps = max(1, n // 2) if required <= n // 2 else n
            self.substep = dt / n

    def _one_record(self, tally: Tally) -> FlightRecord:
        """The record of one interval, kept while the tally's size stays the same."""
        if self._one is None or self._one.counts.shape[1] != tally.counts.shape[0]:
            self._one = FlightRecord.empty(tally, np.zeros(1, dtype=bool))
        return self._one

    def _flight_for(
        self, particles: Particles, vessel: Vessel, field: ForceField, drift: Drift
    ) -> _SmoothFlight | None:
        """The scene's part in the compiled substeps (`_SmoothFlight`), kept while it fits."""
        if self._flight is None or not self._flight.fits(particles, vessel, field, drift):
            self._flight = _SmoothFlight.of(particles, vessel, field, drift)
        return self._flight

    def _flies_with_forces(
        self, particles: Particles, vessel: Vessel, field: ForceField, drift: Drift
    ) -> bool:
        """Whether `_fly_with_forces` may take steps here: forces that the compiled substeps
        take, in a small scene (`_SmoothFlight.of`), and a next interval not left to Python."""
        flight = self._flight_for(particles, vessel, field, drift)
        return not self.next_in_python and flight is not None

    def _fly_with_forces(
        self,
        particles: Particles,
        vessel: Vessel,
        field: ForceField,
        drift: Drift,
        origin: float,
        elapsed: int,
        dt: float,
        tally: Tally,
        record: FlightRecord,
    ) -> int:
        """Whole intervals, compiled (`collidium.kernels.substeps.smooth_intervals`), their
        contacts taken by the exact engine where the scene has one (`_SmoothFlight.engine`):
        `step` takes each such interval by the same call, so both give the same bits."""
        if not self._flies_with_forces(particles, vessel, field, drift):
            return 0
        flight = typing.cast(_SmoothFlight, self._flight)
        with self._processed(particles, vessel, field, dt):
            flown = self._intervals(flight, particles, field, origin, elapsed, dt, tally, record)
        # The interval left meets a contact the compiled substeps leave to Python (or too many
        # substeps, or a value not finite): `step` takes it next, and need not try it again.
        self.next_in_python = flown < record.values.shape[0]
        return flown

    def _intervals(self, flight: _SmoothFlight, particles: Particles, field: ForceField,
                   origin: float, elapsed: int, dt: float, tally: Tally,
                   record: FlightRecord) -> int:  # fmt: skip
        """`_SmoothFlight.intervals` from the substep count kept, which it updates, and the
        energy the drag gave, which it adds to the ``tally``."""
        flown, self.substeps, self.substep = flight.intervals(
            particles, field, origin, elapsed, dt, self.substeps, self.substep, self.tolerance,
            tally, record, self._shown is not None,
        )  # fmt: skip
        if flown:
            tally.forces[0] = record.forces[flown - 1]
        return flown

    def _interval(
        self,
        particles: Particles,
        vessel: Vessel,
        field: ForceField,
        drift: Drift,
        flight: _SmoothFlight | None,
        now: float,
        dt: float,
        tally: Tally,
        n: int,
        fastest: float,
        total: float,
    ) -> tuple[float, bool]:
        """Take the interval in ``n`` regular substeps, those the compiled ``flight`` takes by
        it where there is one (`_SmoothFlight.substeps`), the rest in Python (`_substep`).
        Returns the largest squared rate (1/s^2) met at the boundaries that read it
        (`collidium.kernels.substeps.reads_rate`), starting from ``fastest``, the interval's
        start's (`_squared_rate`, with the ``total`` energy J at the start and the energy given
        since: by the velocity forces, the walls, a piston and inelastic collisions), up to the
        first that needs more than ``n`` substeps, where the interval stops; and whether a
        substep taken in Python met a contact."""
        t = now
        met = False
        given = _given(tally)
        stride = substeps.rate_stride(self.tolerance)
        s = 1
        while s <= n:
            if flight is not None:  # as many substeps as it takes, compiled
                now_total = total + (_given(tally) - given)
                s, t, fastest, drag = flight.substeps(particles, field, tally, now, dt, s, n, t,
                                                      fastest, now_total,
                                                      self.tolerance)  # fmt: skip
                tally.forces[0] += drag
                if s > n:
                    break
            end = now + dt * s / n
            met |= self._substep(particles, vessel, field, drift, t, end, tally, s == n)
            t = end
            if substeps.reads_rate(s, n, stride):
                now_total = total + (_given(tally) - given)
                fastest = max(fastest, _squared_rate(particles, vessel, field, now_total))
                if self.needed(fastest, dt) > n:  # taken again with more
                    break
            s += 1
        # Where the compiled substeps take contacts, Python takes only what they leave.
        return fastest, met and (flight is None or not flight.takes_contacts)

    def _substep(
        self,
        particles: Particles,
        vessel: Vessel,
        field: ForceField,
        drift: Drift,
        t: float,
        end: float,
        tally: Tally,
        last: bool,
    ) -> bool:
        """One kick-drift-kick from ``t`` to ``end`` (s), its contacts inside the drift, their
        kick timing corrected (`_corrected`); it closes the step if it is the interval's
        (``last``). Returns whether it met a contact."""
        h = end - t
        before = _Snapshot(particles, tally)
        acceleration = field.acceleration.copy()
        hits = int(tally.counts.sum())
        log = self._log
        while True:
            log.clear()
            _kick(particles, vessel, field, h, tally)
            drift.drift(particles, vessel, t, h, tally, field.acceleration, field.fall, log)
            if log.complete:
                break
            before.restore(particles, tally)  # with room for all, taken again
            log.make_room()

        def corrected(after: FloatArray) -> None:
            _corrected(log, particles, vessel, field, t, h, before.position, acceleration, after)

        _closing_kick(particles, vessel, field, h, tally, last, corrected if log.count[0] else None)
        return int(tally.counts.sum()) > hits


def _corrected(
    log: ContactLog,
    particles: Particles,
    vessel: Vessel,
    field: ForceField,
    t: float,
    h: float,
    start: FloatArray,
    before: FloatArray,
    after: FloatArray,
) -> None:
    """The second-order correction of the kick timing of the contacts in ``log``, met in the
    substep of ``h`` s from ``t`` (s) that started at positions ``start`` under the accelerations
    ``before`` and ends under ``after`` (`collidium.kernels.kick_timing`), on the velocities
    before the closing kick."""
    width, height = (float(side) for side in vessel.size)
    kick_timing.correct(
        log.rows, int(log.count[0]), t, h, start, particles.position, before, after,
        particles.velocity, writable(particles.mass), *field.pair_laws(particles), width, height,
        vessel.periodic, field.follows_laws(particles, vessel), log.latest(particles.n),
    )  # fmt: skip


def _keep_modified_energy(particles: Particles, vessel: Vessel, field: ForceField,
                          substep: float, following: float, limit: float) -> None:  # fmt: skip
    """Keep the substeps' modified energy from substeps of ``substep`` to ``following`` (s),
    the velocities scaled by at most ``limit``
    (`collidium.kernels.modified_energy.keep_across_step`)."""
    width, height = (float(side) for side in vessel.size)
    modified_energy.keep_across_step(
        particles.position, particles.velocity, field.acceleration, writable(particles.mass),
        *field.pair_laws(particles), width, height, vessel.periodic, np.empty((4, particles.n)),
        substep, following, limit,
    )  # fmt: skip


def _kick(particles: Particles, vessel: Vessel, field: ForceField, h: float, tally: Tally) -> None:
    """What comes before the drift of a substep ``h``: the velocity forces for ``h / 2``, then
    the kick ``a h / 2`` of the position forces."""
    tally.forces[0] += field.advance(particles, vessel, 0.5 * h, first=True)
    particles.velocity += (0.5 * h) * field.acceleration


def _closing_kick(
    particles: Particles,
    vessel: Vessel,
    field: ForceField,
    h: float,
    tally: Tally,
    closes_step: bool = False,
    correction: Callable[[FloatArray], None] | None = None,
) -> None:
    """What comes after the drift, in the mirror order of `_kick`: the forces at the new
    positions (their evaluation `closes_step` or not: `ForceField.evaluate`), the ``correction``
    that needs them if any, their kick ``a h / 2``, then the velocity forces for ``h / 2``."""
    after = field.evaluate(particles, vessel, closes_step)
    if correction is not None:
        correction(after)
    particles.velocity += (0.5 * h) * after
    tally.forces[0] += field.advance(particles, vessel, 0.5 * h, first=False)


def _given(tally: Tally) -> float:
    """The energy (J) given to the particles so far by the velocity forces, the walls, a piston
    and inelastic collisions (negative: taken)."""
    return float(tally.forces[0] + tally.heat.sum())


def _total(particles: Particles, vessel: Vessel, field: ForceField) -> float:
    """The total energy of the particles as they are, J."""
    return sums.kinetic_energy(particles.mass, particles.velocity) + field.potential(
        particles, vessel
    )


def _squared_rate(particles: Particles, vessel: Vessel, field: ForceField, total: float) -> float:
    """The squared rate of the forces weighted by energy, 1/s^2: ``sqrt(S)`` (the energy error per
    squared second of the pair hardest to follow, `ForceField.stiffness`) over the total energy
    ``|KE + U|`` (``total``, J), the scale the energy error is judged against, but never below a
    tenth of ``KE + |U|`` (a total near zero would ask for endless substeps;
    `collidium.kernels.substeps.energy_scale`). A leapfrog step h then errs on the energy by
    about ``h^2 rate^2`` of that scale. The velocity forces' own rate (`ForceField.rate`) counts
    too: a substep turns or damps a velocity by at most ``tolerance`` of it."""
    kinetic = sums.kinetic_energy(particles.mass, particles.velocity)
    scale = substeps.energy_scale(kinetic, total, TOTAL_ENERGY_FLOOR)
    energy = math.sqrt(field.stiffness(particles, vessel)) / scale if scale > 0.0 else 0.0
    return max(energy, field.rate(particles, vessel) ** 2)


#: The forces as the compiled substeps' arguments: the pair force's sources, coupling and squared
#: softening, the uniform field's forces and carried fall, the magnetic field's frequencies and
#: region, the drag's rates (`_SmoothFlight`).
_ForceArguments = tuple[
    FloatArray, float, float, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray
]


@dataclass(frozen=True, eq=False)
class _SmoothFlight:
    """A scene's part in the compiled contact-free substeps (`collidium.kernels.substeps`): the
    vessel and forces it was made for, copies of the masses, radii and charges, the forces as
    the substeps take them (`ForceField.compiled`: the pair force's sources, coupling and
    squared softening, a uniform field's forces and carried fall, a magnetic field's frequencies
    and region, a drag's rates), the walls as the exact engine has them, and under exact
    collisions an engine of its own for the substeps that meet contacts
    (`collidium.collisions.ExactCollisions.substep_engine`; a disabled one where Python takes
    them). The integrator keeps it while it `fits`: making it is most of the Python work of a
    small scene's reporting interval."""

    vessel: Vessel
    field: ForceField
    forces: CompiledForces
    mass: FloatArray
    radius: FloatArray
    charge: FloatArray
    source: FloatArray
    walls: tuple[int, float, float, float, FloatArray]
    drift: Drift
    engine: SubstepEngine

    @classmethod
    def of(
        cls, particles: Particles, vessel: Vessel, field: ForceField, drift: Drift
    ) -> _SmoothFlight | None:
        """The scene's part, or None unless the vessel has walls (not periodic), the particles
        are few enough for one thread (`PARALLEL_DIRECT_FROM`) and the forces are those the
        substeps take (`ForceField.compiled`; a vessel with a piston has no pair sum of
        theirs). A substep that meets no contact is a straight flight in every collision
        mode; one that meets contacts takes the exact engine, where there is one and the drift
        carries no fall."""
        if vessel.periodic or particles.n >= PARALLEL_DIRECT_FROM:
            return None
        forces = field.compiled(particles, vessel)
        if forces is None:
            return None
        half_width, half_height = (0.5 * float(side) for side in vessel.extent)
        walls = (vessel.shape_code, half_width, half_height, vessel.rim, vessel.segments())
        name = forces.source
        source = np.zeros(particles.n) if name is None else getattr(particles, name)
        engine = (
            drift.substep_engine(particles, vessel)
            if isinstance(drift, ExactCollisions) and forces.fall.size == 0
            else None
        ) or SubstepEngine.disabled(vessel)
        # Contiguous copies: the particles' arrays may be edited in place (`fits` compares), and
        # a shared value is a stride-0 view, which would compile the substeps again.
        return cls(vessel, field, forces, np.array(particles.mass), np.array(particles.radius),
                   np.array(particles.charge), np.array(source), walls, drift,
                   engine)  # fmt: skip

    def fits(self, particles: Particles, vessel: Vessel, field: ForceField, drift: Drift) -> bool:
        """Whether this is still the scene's part: the same vessel, forces and drift, and
        particles of the same masses, radii and charges (the uniform field, the magnetic field
        and the pair force's sources are of those)."""
        return (
            vessel is self.vessel
            and field is self.field
            and drift is self.drift
            and np.array_equal(particles.mass, self.mass)
            and np.array_equal(particles.radius, self.radius)
            and np.array_equal(particles.charge, self.charge)
        )

    @property
    def _forces(self) -> _ForceArguments:
        """The forces' arguments of the compiled substeps."""
        f = self.forces
        return (self.source, f.coupling, f.softening2, f.uniform, f.fall, f.turn, f.region,
                f.damp)  # fmt: skip

    def intervals(
        self,
        particles: Particles,
        field: ForceField,
        origin: float,
        elapsed: int,
        dt: float,
        starting: int,
        substep: float,
        tolerance: float,
        tally: Tally,
        record: FlightRecord,
        shows: bool = False,
    ) -> tuple[int, int, float]:
        """Whole intervals, up to ``len(record.values)``, the first taken with ``starting``
        substeps or more (`collidium.kernels.substeps.smooth_intervals`), after one of
        ``substep`` s (NaN for none), up to one that meets a contact left to Python:
        ``(intervals taken, the substep count the next starts from, the last one's substep)``.
        The ``record`` gets the energies and the tallies at each one's end (of the processed
        state where it is wanted, if the integrator ``shows`` one), its ``forces`` the energy the
        velocity forces have given, from the ``tally``'s. The field's acceleration is kept
        current."""
        keep = field.keeps_modified_energy(particles, self.vessel)
        limits = self.vessel.audit_arguments()[1:4]
        flown, after, last, processed, drifts = substeps.smooth_intervals(
            particles.position, particles.velocity, field.acceleration, self.mass, self.radius,
            *self._forces, *self.walls, origin, elapsed, dt, record.values.shape[0], starting,
            substep, keep, tolerance, MAX_SUBSTEPS, TOTAL_ENERGY_FLOOR, float(tally.forces[0]),
            record.values, record.forces, self._contacts(particles, tally), record.counts,
            record.impulse, record.heat, shows, record.wanted, limits,
        )  # fmt: skip
        self._took(processed, drifts)
        return int(flown), int(after), float(last)

    @property
    def takes_contacts(self) -> bool:
        """Whether the compiled substeps take the substeps that meet contacts."""
        return self.engine.sort_every > 0

    def _contacts(self, particles: Particles, tally: Tally) -> tuple[object, ...]:
        """The engine's arguments of the compiled substeps (`smooth_substeps`'s
        ``contacts``), with the ``tally``'s arrays."""
        engine = self.engine
        return (engine.queue, engine.walls, engine.sort_every, engine.reach, engine.log.rows,
                engine.log.count, particles.image, tally.counts, tally.impulse,
                tally.heat)  # fmt: skip

    def _took(self, processed: int, drifts: int) -> None:
        """Count the engine's events and queue builds in the compiled substeps (none for a
        disabled engine)."""
        self.engine.took(int(processed), int(drifts))

    def squared_rate(
        self, particles: Particles, field: ForceField, tally: Tally, total: float
    ) -> float:
        """`_squared_rate` of the current state, compiled (the same to round-off)."""
        _, _, rate2, _ = self.substeps(particles, field, tally, 0.0, 0.0, 1, 0, 0.0, -1.0, total,
                                       math.inf)  # fmt: skip
        return rate2

    def substeps(
        self,
        particles: Particles,
        field: ForceField,
        tally: Tally,
        now: float,
        dt: float,
        first: int,
        count: int,
        t: float,
        fastest: float,
        total: float,
        tolerance: float,
    ) -> tuple[int, float, float, float]:
        """Regular substeps from ``first`` of ``count`` up to the first left to Python
        (`collidium.kernels.substeps.smooth_substeps`, given the ``total`` energy J and the
        integrator's ``tolerance``; their contacts added to the ``tally``): ``(that substep, its
        start in s, the largest squared rate, the energy the drag gave in J)``; the substep is
        past ``count`` also where the rate needs more substeps. The field's acceleration is kept
        current; its energies are summed again when read."""
        s, reached, rate2, drag, processed, drifts = substeps.smooth_substeps(
            particles.position, particles.velocity, field.acceleration, self.mass, self.radius,
            *self._forces, *self.walls, now, dt, first, count, t, fastest, total,
            TOTAL_ENERGY_FLOOR, tolerance, MAX_SUBSTEPS, self._contacts(particles, tally),
        )  # fmt: skip
        self._took(processed, drifts)
        return int(s), float(reached), float(rate2), float(drag)


class _Snapshot:
    """The particles' motion and the tally, to take a drift again from where it started."""

    def __init__(self, particles: Particles, tally: Tally) -> None:
        self.position = particles.position.copy()
        self.velocity = particles.velocity.copy()
        self.image = particles.image.copy()
        self.counts = tally.counts.copy()
        self.impulse = tally.impulse.copy()
        self.heat = tally.heat.copy()
        self.piston = tally.piston.copy()
        self.forces = tally.forces.copy()

    def restore(self, particles: Particles, tally: Tally) -> None:
        """Put everything back as it was taken."""
        particles.position[...] = self.position
        particles.velocity[...] = self.velocity
        particles.image[...] = self.image
        tally.counts[...] = self.counts
        tally.impulse[...] = self.impulse
        tally.heat[...] = self.heat
        tally.piston[...] = self.piston
        tally.forces[...] = self.forces


def shows(particles: Particles, vessel: Vessel, field: ForceField) -> bool:
    """Whether the adaptive integrator shows the processed state
    (`collidium.kernels.processing`): the forces' modified energy is known
    (`ForceField.keeps_modified_energy`) and the vessel's walls stand still (not periodic, no
    piston), which the processing's guard takes."""
    return (
        not vessel.periodic
        and vessel.piston is None
        and field.keeps_modified_energy(particles, vessel)
    )


#: What a processing is of (`_made_with`).
_MadeWith = tuple[ForceField, Vessel, FloatArray, FloatArray, FloatArray]


@dataclass
class _Shown:
    """The adaptive integrator's own state (positions and velocities, N x 2) behind the
    processed one it shows, that shown state as it left it, and its field's evaluation there
    (None after a checkpoint: evaluated again). The processing is of the forces, vessel,
    masses, charges and radii it was made with: `matches` holds while they are the same."""

    position: FloatArray
    velocity: FloatArray
    shown_position: FloatArray
    shown_velocity: FloatArray
    evaluation: Evaluation | None = None
    made_with: _MadeWith | None = None

    @classmethod
    def show(
        cls,
        particles: Particles,
        vessel: Vessel,
        field: ForceField,
        substep: float,
        made_with: _MadeWith | None,
    ) -> _Shown:
        """Keep the particles' state as the integrator's own and put the processed state of
        substeps ``substep`` (s) in its place, a processing ``made_with`` the forces, vessel and
        particles of the step before (`matches` checked them)."""
        own = cls(particles.position.copy(), particles.velocity.copy(), np.empty(0), np.empty(0),
                  field.saved(), made_with)  # fmt: skip
        _process(particles, vessel, field, field.acceleration, processing.SHARE * substep * substep)
        own.shown_position = particles.position.copy()
        own.shown_velocity = particles.velocity.copy()
        return own

    @classmethod
    def behind(
        cls, particles: Particles, vessel: Vessel, field: ForceField, substep: float
    ) -> _Shown:
        """The integrator's own state behind the particles' state taken as shown: the inverse
        processing (the flow back), the particles left as they are."""
        shown_position, shown_velocity = particles.position.copy(), particles.velocity.copy()
        acceleration = field.refresh(particles, vessel)
        _process(particles, vessel, field, acceleration, -processing.SHARE * substep * substep)
        own = cls(particles.position.copy(), particles.velocity.copy(), shown_position,
                  shown_velocity, None, _made_with(particles, vessel, field))  # fmt: skip
        particles.position[...], particles.velocity[...] = shown_position, shown_velocity
        return own

    def matches(self, particles: Particles, vessel: Vessel, field: ForceField) -> bool:
        """Whether the particles hold the state shown, as this left it, of the same forces,
        vessel, masses, charges and radii (after a checkpoint, of those the particles have)."""
        if not (
            np.array_equal(particles.position, self.shown_position)
            and np.array_equal(particles.velocity, self.shown_velocity)
        ):
            return False
        if self.made_with is None:  # restored from a checkpoint, with the particles' own
            self.made_with = _made_with(particles, vessel, field)
        field_then, vessel_then, mass, charge, radius = self.made_with
        p = particles
        return (
            field is field_then
            and vessel is vessel_then
            and np.array_equal(p.mass, mass)
            and np.array_equal(p.charge, charge)
            and np.array_equal(p.radius, radius)
        )

    def resume(self, particles: Particles, vessel: Vessel, field: ForceField) -> None:
        """Put the integrator's own state in the particles, and its field's evaluation."""
        particles.position[...] = self.position
        particles.velocity[...] = self.velocity
        if self.evaluation is None:
            field.refresh(particles, vessel)
        else:
            field.restore(self.evaluation)

    def stacked(self) -> FloatArray:
        """The four states (4, N, 2), for a checkpoint."""
        return np.stack([self.position, self.velocity, self.shown_position, self.shown_velocity])

    @classmethod
    def unstacked(cls, arrays: FloatArray) -> _Shown:
        """Take back what `stacked` gave."""
        position, velocity, shown_position, shown_velocity = (np.array(a) for a in arrays)
        return cls(position, velocity, shown_position, shown_velocity)


def _made_with(particles: Particles, vessel: Vessel, field: ForceField) -> _MadeWith:
    """What the processing is of: the forces and the vessel (by identity), copies of the
    masses, charges and radii."""
    p = particles
    return field, vessel, np.array(p.mass), np.array(p.charge), np.array(p.radius)


def _process(
    particles: Particles, vessel: Vessel, field: ForceField, acceleration: FloatArray, scale: float
) -> None:
    """The particles moved, in place, to their processed state for ``scale`` s^2
    (`collidium.kernels.processing.shown`), given their ``acceleration`` (N, 2)."""
    n = particles.n
    sources, couplings, softenings2 = field.pair_laws(particles)
    curved = np.empty((n, 2))
    processing.curved_velocities(particles.position, particles.velocity,
                                 np.ascontiguousarray(sources), couplings, softenings2,
                                 np.empty((6, n)), curved)  # fmt: skip
    shape, limit_x, limit_y, slack, _ = vessel.audit_arguments()
    position, velocity = np.empty((n, 2)), np.empty((n, 2))
    processing.shown(particles.position, particles.velocity, acceleration, writable(particles.mass),
                     curved, scale, writable(particles.radius),
                     (shape, limit_x, limit_y, slack, vessel.segments()), np.arange(n),
                     np.empty((3, n)), position, velocity)  # fmt: skip
    particles.position[...] = position
    particles.velocity[...] = velocity
