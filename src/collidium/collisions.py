"""How particles move during the drift of a step, and how they collide.

Three modes:

- `ExactCollisions` (``"exact"``): event-driven free flight with exact elastic pair and wall
  collisions (`kernels/events.py`). Its event queue is kept between steps: where a force's kick
  or a user changed velocities, the particles whose velocity changed are predicted again; it is
  built again only where positions, radii or masses changed.
- `StepCollisions` (``"step"``): the seed's method: a plain drift, walls folded back exactly, then
  overlapping approaching pairs resolved one by one in index order (`kernels/stepper.py`).
- `NoCollisions` (``"off"``): disks pass through each other; walls still reflect exactly.

Each mode moves ``particles`` from time ``now`` to ``now + dt`` in place and adds what happened
to a `Tally`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, Protocol

import numpy as np

from collidium.errors import SimulationError
from collidium.kernels import audit, event_flights, event_queue, events, stepper
from collidium.kernels.cells import (
    WINDOW_FROM,
    bounding_box,
    event_grid_shape,
    grid_window,
    window_sides,
)
from collidium.kernels.floats import largest_magnitude
from collidium.kernels.substeps import RECORD
from collidium.kernels.vessels import piston as piston_kernels
from collidium.state import BoolArray, FloatArray, IntArray, Particles, as_given, writable
from collidium.vessels import Vessel
from collidium.vessels.walls import wall_axis

CollisionMode = Literal["exact", "step", "off"]
COLLISION_MODES: tuple[CollisionMode, ...] = ("exact", "step", "off")


#: Entries a tally has without walls: the pair collisions.
_PAIR_ENTRIES = 1


@dataclass
class Tally:
    """Running sums kept by the drift modes since a simulation started, and where the
    vessel's piston is.

    Attributes
    ----------
    counts : ndarray of int64, shape (1 + W,)
        Pair collisions, then hits on each of the vessel's W walls in the order of its
        `Vessel.wall_names` (the box's left, right, bottom, top; the circle's rim; a polygon's
        edges; then the partitions).
    impulse : ndarray of float64, shape (1 + W,)
        The collision virial ``sum r_ij . dp_i`` over pair collisions (kg m^2/s; ``r_ij`` the
        centre-to-centre vector at contact, ``dp_i`` the impulse on i), then the normal momentum
        received by each wall, in the same order (kg m/s).
    heat : ndarray of float64, shape (1 + W,)
        The energy each wall has given the disks (J; negative when it took energy), at the wall
        entries of ``counts``; nonzero only for walls that are not mirrors. A piston's is the
        work it has done on the gas.
    piston : ndarray of float64, shape (2,) or (0,)
        The piston's face position (m) and velocity (m/s) along its axis now; empty without
        a piston (`collidium.vessels.walls.Piston`).
    forces : ndarray of float64, shape (1,)
        The energy the velocity forces (drag, friction, a thermostat) have given the disks (J;
        negative: the heat they took), kept by the integrators.
    """

    counts: IntArray
    impulse: FloatArray
    heat: FloatArray
    piston: FloatArray = field(default_factory=lambda: np.empty(0))
    forces: FloatArray = field(default_factory=lambda: np.zeros(1))

    @classmethod
    def for_walls(cls, walls: int) -> Tally:
        """Zeros for a vessel of ``walls`` walls."""
        size = _PAIR_ENTRIES + walls
        return cls(np.zeros(size, dtype=np.int64), np.zeros(size), np.zeros(size))

    @classmethod
    def for_vessel(cls, vessel: Vessel) -> Tally:
        """Zeros for the vessel's walls, and its piston where it starts."""
        tally = cls.for_walls(len(vessel.wall_names))
        if vessel.piston is not None:
            piston = vessel.piston[1]
            tally.piston = np.array([piston.position, piston.velocity], dtype=float)
        return tally


@dataclass(frozen=True)
class FlightRecord:
    """What a flight (`collidium.integrators.Integrator.fly`) records at the end of each step it
    takes, K rows: what the observers that read no more would have read then.

    Attributes
    ----------
    values : ndarray, shape (K, len(collidium.kernels.substeps.RECORD))
        The kinetic and potential energy and the pair virial (J), the momentum (kg m/s) and the
        sum of the speeds (m/s), as `collidium.simulation.Simulation` sums them; a flight may
        leave the rows of the steps not ``wanted`` unwritten.
    counts, impulse, heat : ndarray, shape (K, 1 + W)
        The `Tally`'s.
    forces : ndarray, shape (K,)
        The `Tally`'s energy given by the velocity forces.
    wanted : ndarray of bool, shape (K,)
        The steps whose ``values`` an observer reads.
    """

    values: FloatArray
    counts: IntArray
    impulse: FloatArray
    heat: FloatArray
    forces: FloatArray
    wanted: BoolArray

    @classmethod
    def empty(cls, tally: Tally, wanted: BoolArray) -> FlightRecord:
        """Rows for ``len(wanted)`` steps of a vessel with ``tally``'s walls, not yet written."""
        steps, size = wanted.shape[0], tally.counts.shape[0]
        return cls(
            np.empty((steps, len(RECORD))),
            np.empty((steps, size), dtype=np.int64),
            np.empty((steps, size)),
            np.empty((steps, size)),
            np.empty(steps),
            wanted,
        )


class ContactLog:
    """The contacts a drift under forces met, for the integrator's correction of their kick
    timing (`collidium.kernels.kick_timing`).

    Attributes
    ----------
    rows : ndarray, shape (K, `collidium.kernels.events.LOG_COLUMNS`)
        One row per contact in the order they happened: the particle, its partner (or ``-1 -
        wall``), the time (s), the contact normal (m), the response's ``1 + e`` and the
        particle's velocity change (m/s) (`collidium.kernels.events.run_events`), then the
        columns the correction works in.
    count : ndarray of int64, shape (1,)
        Contacts met since the last `clear`; more than K when they did not all fit.
    """

    def __init__(self, capacity: int = 64) -> None:
        self.rows = np.empty((capacity, events.LOG_COLUMNS))
        self.count = np.zeros(1, dtype=np.int64)
        self._latest = np.empty(0, dtype=np.int64)

    def latest(self, n: int) -> IntArray:
        """The correction's work array for n particles, -1 everywhere
        (`collidium.kernels.kick_timing.correct`, which leaves it so): kept, not made anew for
        each substep."""
        if self._latest.shape[0] != n:
            self._latest = np.full(n, -1, dtype=np.int64)
        return self._latest

    def clear(self) -> None:
        """Forget the contacts logged."""
        self.count[0] = 0

    @property
    def complete(self) -> bool:
        """Whether every contact since the last `clear` found a row."""
        return int(self.count[0]) <= self.rows.shape[0]

    def make_room(self) -> None:
        """Rows for twice as many contacts as were met (a drift taken again logs them all)."""
        self.rows = np.empty((2 * int(self.count[0]), events.LOG_COLUMNS))


@dataclass(frozen=True, eq=False)
class SubstepEngine:
    """The exact engine as the compiled substeps take it for the drifts that meet contacts
    (`ExactCollisions.substep_engine`).

    Attributes
    ----------
    queue : tuple of ndarray
        The engine's arrays in the order `collidium.kernels.events.rebuild` takes them, then the
        vessel's segments and an empty piston; the queue is built afresh at each drift.
    walls : ndarray
        The vessel's wall table (`collidium.kernels.wall_responses`).
    sort_every : int
        Events between re-sorts of the slots.
    reach : float
        A drift whose largest velocity component times its length exceeds this (m) is refused
        (left to `ExactCollisions.drift`, which names it).
    log : ContactLog
        Where the drifts log their contacts (a drift that overflows it is left to Python).
    drift : ExactCollisions
        The mode whose event and queue counters the substeps add to.
    """

    queue: tuple[np.ndarray, ...]
    walls: FloatArray
    sort_every: int
    reach: float
    log: ContactLog
    drift: ExactCollisions

    @classmethod
    def disabled(cls, vessel: Vessel) -> SubstepEngine:
        """An engine that takes no drift (``sort_every`` 0) but has the types of a real one, so
        that the compiled substeps compile once: they leave every substep that meets a contact
        to Python."""
        arrays = _engine_arrays(1, 1)
        arrays["geometry"] = np.zeros(events.GEOMETRY_SIZE)
        arrays["grid"] = np.zeros(3, dtype=np.int64)
        arrays["piston"] = np.empty(0)
        queue = _queue(arrays, vessel)
        return cls(queue, vessel.wall_table(), 0, 0.0, ContactLog(0), ExactCollisions())

    def took(self, processed: int, drifts: int) -> None:
        """Count the events the compiled drifts processed and the queues they built."""
        self.drift.events += processed
        self.drift.rebuilds += drifts


class Drift(Protocol):
    """A drift mode: moves particles over one step and counts collisions.

    Attributes
    ----------
    carries_fall : bool
        Whether the mode's free flight is a parabola under a uniform acceleration that every
        particle shares (`collidium.forces.base.ForceField.fall`): such a force then gives no
        kicks.
    """

    carries_fall: bool

    def drift(
        self,
        particles: Particles,
        vessel: Vessel,
        now: float,
        dt: float,
        tally: Tally,
        acceleration: FloatArray | None = None,
        fall: FloatArray | None = None,
        log: ContactLog | None = None,
    ) -> None:
        """Move ``particles`` from ``now`` to ``now + dt`` (s), in place, adding to ``tally``.

        ``acceleration`` (N, 2), in m/s^2, is that of the step's half kicks when forces act; a mode
        may use it to time collisions within the step consistently with the kicks. ``fall``
        (2,), in m/s^2, is the acceleration every particle flies under between kicks (zero for
        a mode that does not `carries_fall`). A mode with exact contact times adds each contact
        to ``log`` (with ``acceleration`` given), for the integrator to correct its kick timing
        further; other modes leave it as it is.
        """

    def flies(self, particles: Particles, vessel: Vessel, tally: Tally, fall: FloatArray) -> bool:
        """Whether `fly` may take steps now in ``vessel``, without forces or under a uniform
        gravity ``fall`` (2,) in m/s^2 (zero for none) that the mode carries."""

    def fly(
        self,
        particles: Particles,
        vessel: Vessel,
        origin: float,
        elapsed: int,
        dt: float,
        tally: Tally,
        record: FlightRecord,
        fall: FloatArray,
    ) -> int:
        """Drift up to ``len(record.values)`` steps of ``dt`` (s) in one compiled call, without
        forces or under the uniform gravity ``fall`` it carries (2,) in m/s^2, bit for bit as
        `drift` and the run loop would take them one by one, up to the first that it cannot take;
        returns how many it took, each recorded in ``record`` (with the gravity's potential energy).
        Step k starts at ``origin + (elapsed + k) dt``, the simulation's clock. A step that leaves a
        particle outside the vessel or a value not finite ends the flight, taken, for the run loop's
        audit to report."""

    def vouch(self) -> None:
        """Say that the particles are as this mode's last drift left them, and stay so up to
        its next drift: that drift may skip checking them (the run loop knows it between two
        steps that nothing else touched)."""

    def state(self) -> dict[str, np.ndarray]:
        """Arrays a checkpoint needs to continue bit for bit (empty if the mode keeps none)."""

    def load_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Take back what `state` returned."""

    def forget(self) -> None:
        """Drop what the mode keeps of the vessel (the next drift starts afresh): the vessel
        has changed."""


#: Normal approach speed (m/s) below which an inelastic pair collision is elastic: the guard
#: against inelastic collapse, where a cluster of disks would collide infinitely often in a
#: finite time (a restitution that tends to 1 at low impact speed, as real grains show).
ELASTIC_BELOW = 1e-6


def make_drift(mode: CollisionMode, restitution: float = 1.0) -> Drift:
    """The drift object for a collision mode name, with the pair collisions' normal restitution
    (1: elastic)."""
    if mode == "exact":
        return ExactCollisions(restitution)
    if mode == "step":
        return StepCollisions(restitution)
    return NoCollisions()


_NO_ACCELERATION = np.empty((0, 2))
_NO_FALL = np.zeros(2)


def _free_flight(particles: Particles, vessel: Vessel, dt: float, tally: Tally) -> None:
    p = particles
    vessel.free_flight(
        p.position, p.velocity, p.radius, p.mass, p.image, dt, tally.counts[1:],
        tally.impulse[1:], tally.heat[1:],
    )  # fmt: skip


#: Vessel widths (its bounding box's shorter side) a particle may cross in one drift before the
#: state counts as runaway (the event count of a drift grows with it; legitimate runs stay many
#: orders of magnitude below).
MAX_CROSSINGS_PER_DRIFT = 1e9


def _refuse_runaway(
    particles: Particles, vessel: Vessel, dt: float, fall: FloatArray = _NO_FALL
) -> None:
    """Stop before an event-driven drift whose event count would be astronomical (a fall of
    ``fall`` m/s^2 adds its speed after dt)."""
    if particles.n == 0:
        return
    velocity = particles.velocity
    # The flights' rule (`event_flights`), in one pass without a temporary (N, 2).
    speed = float(largest_magnitude(velocity)) + float(np.abs(fall).max()) * dt
    if speed * dt > _runaway_reach(vessel):
        fastest = int(np.abs(velocity).max(axis=1).argmax())
        raise SimulationError(
            f"particle {fastest} moves at {speed:.3g} m/s, over {MAX_CROSSINGS_PER_DRIFT:.0g} "
            "vessel widths per step: the state has run away; try a smaller dt or softening"
        )


def _runaway_reach(vessel: Vessel) -> float:
    """The distance (m) past which a drift's largest velocity component times dt counts as
    runaway (`MAX_CROSSINGS_PER_DRIFT`)."""
    return MAX_CROSSINGS_PER_DRIFT * float(vessel.size.min())


class _Stateless:
    """A mode whose drift depends on the particles alone (work arrays are rebuilt identically)
    and flies straight between kicks."""

    carries_fall = False

    def state(self) -> dict[str, np.ndarray]:
        """Nothing to save."""
        return {}

    def load_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Nothing to restore."""

    def forget(self) -> None:
        """Nothing kept."""

    def vouch(self) -> None:
        """Nothing checked (`Drift.vouch`)."""

    def flies(self, particles: Particles, vessel: Vessel, tally: Tally, fall: FloatArray) -> bool:
        """Never: each step is its own call (`Drift.flies`)."""
        return False

    def fly(
        self,
        particles: Particles,
        vessel: Vessel,
        origin: float,
        elapsed: int,
        dt: float,
        tally: Tally,
        record: FlightRecord,
        fall: FloatArray,
    ) -> int:
        """No steps (`Drift.fly`)."""
        return 0


class NoCollisions(_Stateless):
    """Pass-through: free flight with exact wall reflection (or periodic wrapping)."""

    def drift(
        self,
        particles: Particles,
        vessel: Vessel,
        now: float,
        dt: float,
        tally: Tally,
        acceleration: FloatArray | None = None,
        fall: FloatArray | None = None,
        log: ContactLog | None = None,
    ) -> None:
        """Move ``particles`` from ``now`` to ``now + dt`` (s), in place (logs no contact)."""
        _free_flight(particles, vessel, dt, tally)


class StepCollisions(_Stateless):
    """The seed's method: drift, fold back from walls, resolve overlapping pairs in index order.

    A collision is only detected if the disks overlap at the end of a step, so fast or small disks
    can pass through each other; energy is still conserved by each resolved collision.

    The pair search keeps the particles sorted into a cell grid of its own
    (`stepper.step_grid`), updated from step to step; the grid is kept while the number of
    particles and the vessel stay the same and no disk grows past the diameter it was made for.
    Its arrays take about 80 bytes per particle (90 when the radii differ).
    """

    #: Bands of rows searched in parallel (at most one per row of cells).
    SEARCH_CHUNKS = 256

    def __init__(self, restitution: float = 1.0) -> None:
        self.restitution = restitution
        self._layout: tuple[int, float, float, bool] | None = None
        self._window = np.zeros((2, 2))  # the rectangle the cells cover (`grid_window`)
        self._whole = True  # whether that is the vessel's whole bounding box
        self._diameter = 0.0
        self._sorted = False  # whether the cell order of the step before is at hand
        self._radius = np.empty(0)  # the radii seen at the step before
        self._pairs = np.empty(0, dtype=np.int64)
        self._scratch = np.empty(0, dtype=np.int64)

    def _make_grid(self, particles: Particles, vessel: Vessel, diameter: float) -> None:
        n = particles.n
        width, height = (float(side) for side in vessel.extent)
        self._layout = (n, width, height, vessel.periodic)
        self._diameter = diameter
        self._sorted = False
        self._window = grid_window(particles.position, diameter, vessel.extent, vessel.periodic)
        self._whole = _covers(self._window, vessel.extent)
        sides = window_sides(self._window)
        ncx, ncy, self._general = stepper.step_grid(*sides, diameter, n, vessel.periodic)
        self._shape = (ncx, ncy)
        self._chunks = min(self.SEARCH_CHUNKS, ncy)
        index = np.int32 if max(n, ncx * ncy) < 2**31 - 1 else np.int64
        self._start = np.empty(ncx * ncy + 1, dtype=index)
        self._cursor = np.empty(ncx * ncy, dtype=index)
        self._order, self._order_out = np.empty(n, index), np.empty(n, index)
        self._key, self._key_out = np.empty(n, index), np.empty(n, index)
        self._new_key = np.empty(n, dtype=index)
        self._movers = np.empty(n, dtype=index)
        self._grouped = np.empty(n, dtype=index)
        self._moved = np.empty(stepper.chunk_count(n), dtype=np.int64)
        self._data_xy, self._cell_xy = np.empty((n, 2)), np.empty((n, 2))
        self._data_r, self._cell_r = np.empty(n), np.empty(n)
        if self._pairs.shape[0] < self._chunks * 64:
            self._pairs = np.empty(self._chunks * max(64, n // (8 * self._chunks)), dtype=np.int64)
            self._scratch = np.empty_like(self._pairs)

    def _sort(self, particles: Particles, vessel: Vessel, fresh: bool, uniform: bool) -> None:
        """Sort the particles into cells (from last step's order when there is one)."""
        if self._sorted:
            stepper.gather_movers(
                particles.position, particles.radius, fresh, uniform, self._window,
                *self._shape, self._order, self._key, self._cell_r, self._data_xy, self._data_r,
                self._new_key, self._movers, self._moved,
            )  # fmt: skip
            self._sorted = stepper.update_cells(
                uniform, *self._shape, self._order, self._key, self._data_xy, self._data_r,
                self._new_key, self._movers, self._grouped, self._moved, self._order_out,
                self._key_out, self._start, self._cell_xy, self._cell_r,
            )  # fmt: skip
            if self._sorted:
                self._order, self._order_out = self._order_out, self._order
                self._key, self._key_out = self._key_out, self._key
                return
        stepper.sort_into_cells(
            particles.position, particles.radius, uniform, self._window, *self._shape,
            self._movers, self._data_xy, self._data_r, self._cursor, self._order, self._key,
            self._start, self._cell_xy, self._cell_r,
        )  # fmt: skip
        self._sorted = True

    def _radius_summary(self, radius: FloatArray) -> tuple[bool, bool, float]:
        """``(changed since the last step, all equal, largest in m)``: for a radius all particles
        share, without a pass over N radii or a copy of them."""
        shared = as_given(radius)
        if isinstance(shared, float):
            changed = self._radius.shape != (1,) or shared != self._radius[0]
            self._radius = np.array([shared])
            return changed, True, shared
        if self._radius.shape != radius.shape:
            self._radius = np.full(radius.shape, np.nan)
        return stepper.radius_summary(radius, self._radius)

    def drift(
        self,
        particles: Particles,
        vessel: Vessel,
        now: float,
        dt: float,
        tally: Tally,
        acceleration: FloatArray | None = None,
        fall: FloatArray | None = None,
        log: ContactLog | None = None,
    ) -> None:
        """Move ``particles`` from ``now`` to ``now + dt`` (s), in place (logs no contact)."""
        _free_flight(particles, vessel, dt, tally)
        if particles.n == 0:
            return
        changed, uniform, largest = self._radius_summary(particles.radius)
        width, height = (float(side) for side in vessel.extent)
        layout = (particles.n, width, height, vessel.periodic)
        # Cells must stay at least a diameter wide; they are kept if the disks shrink. A window
        # short of the vessel is made again once disks have left it.
        if (
            layout != self._layout
            or 2.0 * largest > self._diameter
            or not (self._whole or _inside(particles.position, self._window))
        ):
            self._make_grid(particles, vessel, 2.0 * largest)
            changed = True
        if uniform and changed:  # equal radii: the same in every order, left alone by the sort
            self._cell_r.fill(largest)
        self._sort(particles, vessel, changed, uniform)
        while True:
            count = stepper.overlapping_pairs(
                self._start, self._order, self._cell_xy, self._cell_r, uniform, largest,
                *self._shape, width, height, vessel.periodic, self._general, self._chunks,
                self._pairs, self._scratch,
            )  # fmt: skip
            if count >= 0:
                break
            self._pairs = np.empty(2 * self._chunks * -count, dtype=np.int64)
            self._scratch = np.empty_like(self._pairs)
        tally.counts[0] += stepper.resolve_pairs(
            self._pairs[:count], particles.position, particles.velocity, particles.mass,
            width, height, vessel.periodic, tally.impulse, self.restitution, ELASTIC_BELOW,
            tally.heat,
        )  # fmt: skip


class ExactCollisions:
    """Event-driven drift: exact collision times and exact elastic responses.

    The engine keeps lazily updated positions of its own, in its own order
    (`collidium.kernels.events`); ``particles.position`` and ``particles.velocity`` receive the
    state at the end of each drift. Where only velocities differ from what the engine last wrote
    (a force's kick, an edit by the user), the particles whose velocity changed are predicted
    again and the other events kept (`collidium.kernels.events.refresh`); where positions, radii
    or masses differ, the queue is built again from the particles. Under a uniform gravity the
    free flights are exact parabolas (`carries_fall`), so the queue lives on then too.
    """

    carries_fall = True

    def __init__(self, restitution: float = 1.0) -> None:
        #: Normal restitution of the pair collisions (1: elastic).
        self.restitution = restitution
        self._state: dict[str, np.ndarray] | None = None
        self._spare: dict[str, np.ndarray] | None = None  # arrays of a queue no longer valid
        self._synced_at = 0.0  # time (s) at which the particles were last written
        #: Events processed so far (collisions, wall hits, cell crossings, stale events).
        self.events = 0
        #: Times the event queue was built from scratch.
        self.rebuilds = 0
        #: Times it was kept with the particles whose velocity changed predicted again, and how
        #: many such particles in all.
        self.refreshes = self.repredicted = 0
        #: Events per particle between re-sorts of the engine's memory by cell (speed only);
        #: None for `events.sort_interval`'s, by the number of particles.
        self.sort_interval: int | None = None
        #: The contact log of drifts that are given none (never written: no forces).
        self._unlogged = ContactLog(0)
        #: Where a flight leaves the piston's face (`Tally.piston`'s two values).
        self._piston_now = np.zeros(2)
        #: Whether the next drift may take the particles as the last one wrote them (`vouch`).
        self._vouched = False

    def state(self) -> dict[str, np.ndarray]:
        """The event queue and lazily updated positions, and the event counters."""
        out: dict[str, np.ndarray] = {
            "events": np.array(
                [self.events, self.rebuilds, self.refreshes, self.repredicted], dtype=np.int64
            ),
            "event_codes": np.array([_EVENT_CODES]),
        }
        if self._state is not None:
            out |= {
                f"queue/{name}": array
                for name, array in self._state.items()
                if name not in _SLOT_VIEWS
            }
            out["synced_at"] = np.array([self._synced_at])
        return out

    def load_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Continue from a saved queue (or rebuild it at the next drift if none was saved, or
        one of another layout)."""
        counters = [int(x) for x in arrays["events"]]
        counters += [0] * (4 - len(counters))  # saved before the queue was refreshed: none
        self.events, self.rebuilds, self.refreshes, self.repredicted = counters
        queue = {k.removeprefix("queue/"): v for k, v in arrays.items() if k.startswith("queue/")}
        queue.setdefault("piston", np.empty(0))  # saved before pistons: none
        usable = (
            set(queue) == {*_QUEUE_ARRAYS, "piston"}
            and "synced_at" in arrays
            and int(arrays.get("event_codes", [0])[0]) == _EVENT_CODES
        )
        self._state = _restored(queue) if usable else None
        self._synced_at = float(arrays["synced_at"][0]) if usable else 0.0

    def forget(self) -> None:
        """Drop the event queue (its arrays are reused by the next rebuild)."""
        if self._state is not None:
            self._spare, self._state = self._state, None

    def vouch(self) -> None:
        """Skip, at the next drift, the check that the particles are as the last one wrote them
        (`Drift.vouch`): `collidium.kernels.events.refresh`'s pass over every particle in slot
        order, reading each at random, 0.3-0.5 ms at 1e5 disks on two cores."""
        self._vouched = True

    def _up_to_date(
        self,
        particles: Particles,
        vessel: Vessel,
        piston: FloatArray,
        fall: FloatArray,
        vouched: bool = False,
    ) -> bool:
        """Whether the queue holds the particles, now brought up to date with any velocities
        changed since the last drift wrote them (`collidium.kernels.events.refresh`); False where
        it must be built again: none kept, another number of particles, gravity or piston, or
        positions, radii or masses changed."""
        s = self._state
        if s is None or s["body"].shape[0] != particles.n:
            return False
        if not np.array_equal(s["geometry"][[events.FALL_X, events.FALL_Y]], fall):
            return False
        if not np.array_equal(_piston_now(s["piston"], self._synced_at), piston):
            return False
        if vouched:
            return True
        p = particles
        refresh = events.refresh_in_chunks if _many(p) else events.refresh
        arguments = (*_queue(s, vessel), p.position, p.velocity, p.radius, p.mass)
        changed = int(refresh(self._synced_at, *arguments))
        if changed > 0:
            self.refreshes += 1
            self.repredicted += changed
        return changed >= 0

    def _rebuild(
        self,
        particles: Particles,
        vessel: Vessel,
        now: float,
        piston: FloatArray,
        fall: FloatArray = _NO_FALL,
    ) -> dict[str, np.ndarray]:
        # Arrays of the same shapes are filled again rather than allocated (with forces the queue
        # is rebuilt at every substep).
        old = self._state if self._state is not None else self._spare
        self._spare = None
        s = self._layout(particles, vessel, fall, old)
        events.load(
            particles.position, particles.velocity, particles.radius, particles.mass,
            s["body"], s["event"],
        )  # fmt: skip
        s["piston"] = (
            vessel.piston_array(float(piston[0]), float(piston[1]), now)
            if piston.size
            else np.empty(0)
        )
        rebuild = events.rebuild_in_chunks if _many(particles) else events.rebuild
        rebuild(now, *_queue(s, vessel))
        return s

    def _layout(
        self,
        particles: Particles,
        vessel: Vessel,
        fall: FloatArray,
        old: dict[str, np.ndarray] | None = None,
    ) -> dict[str, np.ndarray]:
        """The engine's arrays for the particles where they are (``old``'s where they have the
        shapes needed), with its geometry and grid; the queue not built."""
        n = particles.n
        diameter = 2.0 * float(particles.radius.max(initial=0.0))
        window = grid_window(particles.position, diameter, vessel.extent, vessel.periodic)
        width, height = window_sides(window)
        ncx, ncy = event_grid_shape(
            width, height, diameter, n, falls=bool(np.any(fall)), segments=len(vessel.segments())
        )
        shared = _shared_radius_and_mass(particles)
        columns = events.BODY_COLUMNS if shared is None else events.SHARED_BODY_COLUMNS
        if old is not None and old["body"].shape == (n, columns) and old["head"].size == ncx * ncy:
            s = old
        else:
            s = _engine_arrays(n, ncx * ncy, columns)
        half_width, half_height = (0.5 * float(side) for side in vessel.extent)
        s["geometry"] = np.array(
            [half_width, half_height, width / ncx, height / ncy, *(shared or (np.nan, np.nan)),
             vessel.shape_code, vessel.rim, self.restitution, ELASTIC_BELOW, *window[0], *fall]
        )  # fmt: skip
        s["grid"] = np.array([ncx, ncy, int(vessel.periodic)], dtype=np.int64)
        return s

    def _sort_every(self, n: int) -> int:
        """Events between re-sorts of the slots for n particles (`sort_interval` a particle)."""
        interval = events.sort_interval(n) if self.sort_interval is None else self.sort_interval
        return max(1, interval * n)

    def substep_engine(self, particles: Particles, vessel: Vessel) -> SubstepEngine | None:
        """An engine of its own for the compiled substeps' drifts that meet contacts
        (`collidium.kernels.substeps`), which build its queue afresh at each; None where they
        cannot take them: a periodic box, a piston, or so many disks that the cells' window
        follows them (`collidium.kernels.cells.grid_window`)."""
        if vessel.periodic or vessel.piston is not None or particles.n >= WINDOW_FROM:
            return None
        s = self._layout(particles, vessel, _NO_FALL)
        s["piston"] = np.empty(0)
        return SubstepEngine(
            _queue(s, vessel),
            vessel.wall_table(),
            self._sort_every(particles.n),
            _runaway_reach(vessel),
            ContactLog(max(64, 4 * particles.n)),
            self,
        )

    def drift(
        self,
        particles: Particles,
        vessel: Vessel,
        now: float,
        dt: float,
        tally: Tally,
        acceleration: FloatArray | None = None,
        fall: FloatArray | None = None,
        log: ContactLog | None = None,
    ) -> None:
        """Move ``particles`` from ``now`` to ``now + dt`` (s), in place, logging the contacts
        under forces (`Drift.drift`)."""
        # Taken first: a drift that raises leaves no vouch for the particles a user may then
        # change.
        vouched, self._vouched = self._vouched and self._synced_at == now, False
        fall = _NO_FALL if fall is None else fall
        _refuse_runaway(particles, vessel, dt, fall)
        if not self._up_to_date(particles, vessel, tally.piston, fall, vouched):
            self._state = self._rebuild(particles, vessel, now, tally.piston, fall)
            self.rebuilds += 1
        s = self._state
        assert s is not None
        until = now + dt
        log = self._unlogged if log is None or acceleration is None else log
        processed = events.run_events(
            until, s["body"], particles.image, s["geometry"], s["grid"], s["head"], s["next"],
            s["event"], s["keys"], s["items"], tally.counts, tally.impulse,
            _NO_ACCELERATION if acceleration is None else acceleration, now + 0.5 * dt,
            self._sort_every(particles.n), log.rows, log.count, vessel.wall_table(),
            tally.heat, vessel.segments(), s["piston"],
        )  # fmt: skip
        if processed < 0:
            self._state = None  # the queue is unusable; a later drift rebuilds it
            stuck = -1 - processed
            raise SimulationError(
                f"particle {stuck}: time stopped advancing in the event-driven drift near "
                f"t = {until:.6g} s (velocity {particles.velocity[stuck].tolist()} m/s at the "
                "step's start); the state has run away: try a smaller dt or softening"
            )
        self.events += processed
        synchronise = events.synchronise_in_chunks if _many(particles) else events.synchronise
        strays = synchronise(
            until, s["body"], s["event"], s["geometry"], s["grid"], particles.position,
            particles.velocity,
        )  # fmt: skip
        tally.piston[...] = _piston_now(s["piston"], until)
        self._synced_at = until
        if strays and s["grid"][2] == 0 and not _window_is_vessel(s["geometry"], s["grid"]):
            # Disks have spread out of the cells' window: a larger one at the next drift.
            self._spare, self._state = self._state, None

    def flies(self, particles: Particles, vessel: Vessel, tally: Tally, fall: FloatArray) -> bool:
        """Whether `fly` may take steps now: the queue is built for this ``fall`` and holds the
        particles (brought up to date with velocities changed since it wrote them), and they are
        fewer than `collidium.kernels.audit.PARALLEL_FROM` (`Drift.flies`). With more, a step takes
        milliseconds, its Python is nothing beside them, and the run loop's audit and the
        engine's passes over every particle run on every core where the flight's would run on
        one (a 1e5-disk gas's step took 7-10% longer flown, before those passes were
        parallel)."""
        return not _many(particles) and self._up_to_date(particles, vessel, tally.piston, fall)

    def fly(
        self,
        particles: Particles,
        vessel: Vessel,
        origin: float,
        elapsed: int,
        dt: float,
        tally: Tally,
        record: FlightRecord,
        fall: FloatArray,
    ) -> int:
        """Steps in one compiled call (`Drift.fly`,
        `collidium.kernels.event_flights.event_intervals`). The record holds no piston: with
        one, the simulation asks for no step of it (`Simulation._reads_state`)."""
        if not self.flies(particles, vessel, tally, fall):
            return 0
        s = self._state
        assert s is not None
        before = (tally.counts.copy(), tally.impulse.copy(), tally.heat.copy())
        fall_x, fall_y = (float(g) for g in fall)
        width, height = (float(side) for side in vessel.size)
        face = vessel.piston_face()
        p = particles
        taken, processed, ending = event_flights.event_intervals(
            origin, elapsed, dt, record.values.shape[0], s["body"], p.image, s["geometry"],
            s["grid"], s["head"], s["next"], s["event"], s["keys"], s["items"], tally.counts,
            tally.impulse, _NO_ACCELERATION, self._sort_every(p.n),
            self._unlogged.rows, self._unlogged.count, vessel.wall_table(), tally.heat,
            vessel.segments(), s["piston"], p.position,
            p.velocity, writable(p.mass), writable(p.radius), fall_x, fall_y, width, height,
            _runaway_reach(vessel),
            *vessel.audit_arguments(), bool(s["grid"][2]) or _window_is_vessel(s["geometry"],
            s["grid"]), 0.0 if face is None else face[3], self._piston_now, record.values,
            record.counts, record.impulse, record.heat, record.wanted,
        )  # fmt: skip
        self.events += processed
        if taken:
            self._synced_at = origin + (elapsed + taken - 1) * dt + dt  # as `drift` adds them
            tally.piston[...] = self._piston_now[: tally.piston.size]
        if ending == event_flights.OUT_OF_WINDOW:
            self._spare, self._state = self._state, None  # as `drift`: a larger window next
        elif ending < 0:
            # Time stopped advancing in the step after those taken: the drift takes it again
            # from the particles as the last step wrote them, and says where it stopped.
            self._state = None
            rows = (record.counts, record.impulse, record.heat)
            kept = before if taken == 0 else tuple(row[taken - 1] for row in rows)
            for now, then in zip((tally.counts, tally.impulse, tally.heat), kept, strict=True):
                now[...] = then
        return int(taken)


def _many(particles: Particles) -> bool:
    """Whether the engine's passes over every particle (writing them at a step's end, checking
    them at the next step's start) run in parallel chunks, as the audit's do: from
    `collidium.kernels.audit.PARALLEL_FROM` particles (a 1e5-disk gas: 0.7 and 1.2 ms a step
    on one core)."""
    return particles.n >= audit.PARALLEL_FROM


def _window_is_vessel(geometry: FloatArray, grid: np.ndarray) -> bool:
    """Whether the engine's cells cover the vessel's whole bounding box."""
    g = events
    low = geometry[[g.GRID_LEFT, g.GRID_BOTTOM]]
    high = low + grid[:2] * geometry[[g.CELL_WIDTH, g.CELL_HEIGHT]]
    return _covers(np.array([low, high]), 2.0 * geometry[[g.HALF_WIDTH, g.HALF_HEIGHT]])


def _covers(window: FloatArray, extent: tuple[float, float] | FloatArray) -> bool:
    """Whether a cells' window ``[[x0, y0], [x1, y1]]`` (m) covers a vessel's bounding box of
    sides ``extent`` (m), centred on the origin."""
    half = 0.5 * np.asarray(extent, dtype=np.float64)
    return bool((window[0] <= -half).all() and (window[1] >= half).all())


def _inside(position: FloatArray, window: FloatArray) -> bool:
    """Whether every point of ``position`` (N, 2) lies in ``window`` (m)."""
    if position.shape[0] == 0:
        return True
    x0, y0, x1, y1 = bounding_box(position)
    return bool(
        window[0, 0] <= x0 and window[0, 1] <= y0 and x1 <= window[1, 0] and y1 <= window[1, 1]
    )


def _piston_now(piston: FloatArray, t: float) -> FloatArray:
    """The engine's piston (`collidium.kernels.vessels.piston`) as `Tally.piston`: its face's
    position (m) and velocity (m/s) along its axis at time t (s); empty for none."""
    if piston.size == 0:
        return piston
    k = piston_kernels
    _, sign = wall_axis(int(piston[k.WALL]))
    height, speed = k.motion(piston, t)
    return np.array([sign * height, sign * speed])


def _cache_aligned_rows(n: int, columns: int, dtype: type = np.float64) -> np.ndarray:
    """An empty (n, columns) array that starts on a 64-byte cache line, and so every row if the
    row size divides 64.

    The engine reads a neighbour as one row, and the event queue a block or a heap node's
    children as one group (`collidium.kernels.event_queue`); large arrays come from the allocator
    16 bytes past a line, and a row or group would then span two lines.
    """
    itemsize = np.dtype(dtype).itemsize
    per_line = 64 // itemsize
    buffer: np.ndarray = np.empty(n * columns + per_line, dtype=dtype)
    skip = (-buffer.ctypes.data % 64) // itemsize
    return buffer[skip : skip + n * columns].reshape(n, columns)


def _shared_radius_and_mass(particles: Particles) -> tuple[float, float] | None:
    """The one radius (m) and mass (kg) of every particle, or None if they differ: the engine
    then keeps them in ``geometry`` and its rows are a quarter smaller (`events`)."""
    radius, mass = particles.radius, particles.mass
    if particles.n and (radius == radius[0]).all() and (mass == mass[0]).all():
        return float(radius[0]), float(mass[0])
    return None


def _engine_arrays(n: int, cells: int, columns: int = events.BODY_COLUMNS) -> dict[str, np.ndarray]:
    """Empty engine arrays for n particles and a grid of ``cells`` (all but geometry and grid),
    with ``body`` rows of ``columns`` (`events.BODY_COLUMNS` or `events.SHARED_BODY_COLUMNS`).

    A slot's integers share one 24-byte row of ``event``: ``ident``, ``cell_of`` and ``count``
    are views of its last columns, so the engine reads a slot in two rows (its ``body`` row and
    this one). ``keys`` and ``items`` hold the event queue (`collidium.kernels.event_queue`).
    """
    index = np.int32
    rows = _cache_aligned_rows(n, events.SLOT_COLUMNS, index)
    times, slots = event_queue.sizes(n)
    views = {name: rows[:, column] for name, column in _SLOT_VIEWS.items()}
    views["ident"][...] = np.arange(n)  # slot k holds particle k until the first sort
    return {
        "body": _cache_aligned_rows(n, columns),
        "head": np.empty(cells, dtype=index),
        "next": np.empty(n, dtype=index),
        "event": rows,
        "keys": _cache_aligned_rows(times, 1)[:, 0],
        "items": _cache_aligned_rows(slots, 1, index)[:, 0],
    } | views


def _restored(saved: dict[str, np.ndarray]) -> dict[str, np.ndarray] | None:
    """Engine arrays laid out as `_engine_arrays` with the saved values, or None if the saved
    rows or geometry are not of this engine's layout (an earlier version's)."""
    n, width = saved["event"].shape
    columns = saved["body"].shape[1]
    if (
        width != events.SLOT_COLUMNS
        or columns not in (events.BODY_COLUMNS, events.SHARED_BODY_COLUMNS)
        or saved["geometry"].shape != (events.GEOMETRY_SIZE,)
    ):
        return None
    arrays = _engine_arrays(n, saved["head"].shape[0], columns)
    for name, array in arrays.items():
        if name not in _SLOT_VIEWS:
            array[...] = saved[name]
    return arrays | {name: np.array(saved[name]) for name in ("geometry", "grid", "piston")}


#: The layout of the engine's saved queues (2: walls after the cell crossings, any number of
#: them; 3: the pairs' restitution in ``geometry``; 4: the cells' window there too; 5: and the
#: gravity the disks fall with; 6: the queue of blocks, `collidium.kernels.event_queue`); a queue
#: saved with another is rebuilt, not read.
_EVENT_CODES = 6


#: The engine's arrays that are views of columns of ``event`` (`_engine_arrays`).
_SLOT_VIEWS = {
    "ident": events.IDENT, "cell_of": events.CELL, "count": events.COUNT,
}  # fmt: skip


#: The engine's arrays in the order `events.rebuild` takes them (the slot views are taken there,
#: from ``event``).
_QUEUE_ARRAYS = ("body", "geometry", "grid", "head", "next", "event", "keys", "items")


def _queue(state: dict[str, np.ndarray], vessel: Vessel) -> tuple[np.ndarray, ...]:
    """The engine's arrays of ``state`` in the order `collidium.kernels.events.rebuild` takes
    them, then the vessel's segments and the state's piston."""
    return (*(state[name] for name in _QUEUE_ARRAYS), vessel.segments(), state["piston"])
