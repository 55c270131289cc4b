"""How particles move during the drift of a step, and how they collide.

Three modes (DESIGN.md section 2):

- `ExactCollisions` (``"exact"``): event-driven free flight with exact elastic pair and wall
  collisions (`kernels/events.py`). Its event queue is kept between steps and rebuilt only when the
  state was changed from outside (a force kick, a user edit).
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

from collidium.containers import Box
from collidium.errors import SimulationError
from collidium.kernels import events, stepper, walls
from collidium.kernels.cells import grid_shape, neighbour_table
from collidium.state import FloatArray, IntArray, Particles

CollisionMode = Literal["exact", "step", "off"]
COLLISION_MODES: tuple[CollisionMode, ...] = ("exact", "step", "off")


def _zeros_int() -> IntArray:
    return np.zeros(5, dtype=np.int64)


def _zeros_float() -> FloatArray:
    return np.zeros(5)


@dataclass
class Tally:
    """Running sums kept by the drift modes since a simulation started.

    Attributes
    ----------
    counts : ndarray of int64, shape (5,)
        Pair collisions, then hits on the left, right, bottom and top wall.
    impulse : ndarray of float64, shape (5,)
        The collision virial ``sum r_ij . dp_i`` over pair collisions (kg m^2/s; ``r_ij`` the
        centre-to-centre vector at contact, ``dp_i`` the impulse on i), then the normal momentum
        received by the left, right, bottom and top wall (kg m/s).
    """

    counts: IntArray = field(default_factory=_zeros_int)
    impulse: FloatArray = field(default_factory=_zeros_float)


class Drift(Protocol):
    """A drift mode: moves particles over one step and counts collisions."""

    def drift(
        self,
        particles: Particles,
        box: Box,
        now: float,
        dt: float,
        tally: Tally,
        acceleration: FloatArray | None = None,
    ) -> None:
        """Move ``particles`` from ``now`` to ``now + dt`` (s), in place, adding to ``tally``.

        ``acceleration`` (N, 2), in m/s^2, is that of the step's half kicks when forces act; a mode
        may use it to time collisions within the step consistently with the kicks.
        """

    def state(self) -> dict[str, np.ndarray]:
        """Arrays a checkpoint needs to continue bit for bit (empty if the mode keeps none)."""

    def load_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Take back what `state` returned."""


def make_drift(mode: CollisionMode) -> Drift:
    """The drift object for a collision mode name."""
    modes: dict[str, type[ExactCollisions | StepCollisions | NoCollisions]] = {
        "exact": ExactCollisions,
        "step": StepCollisions,
        "off": NoCollisions,
    }
    return modes[mode]()


_NO_ACCELERATION = np.empty((0, 2))


class _Grid:
    """Cell grid sized for the particles' largest diameter, with work arrays."""

    def __init__(self, particles: Particles, box: Box) -> None:
        n = particles.n
        diameter = 2.0 * float(particles.radius.max(initial=0.0))
        self.shape = grid_shape(box.width, box.height, diameter, n)
        ncx, ncy = self.shape
        self.cells, self.shifts = neighbour_table(ncx, ncy, box.periodic)
        self.cell_of = np.empty(n, dtype=np.int64)
        self.head = np.empty(ncx * ncy, dtype=np.int64)
        self.next = np.empty(n, dtype=np.int64)
        self.prev = np.empty(n, dtype=np.int64)


def _free_flight(particles: Particles, box: Box, dt: float, tally: Tally) -> None:
    if box.periodic:
        walls.drift_periodic(
            particles.position, particles.velocity, particles.image, box.width, box.height, dt
        )
    else:
        walls.drift_reflecting(
            particles.position, particles.velocity, particles.radius, particles.mass,
            0.5 * box.width, 0.5 * box.height, dt, tally.counts[1:], tally.impulse[1:],
        )  # fmt: skip


#: Box sides a particle may cross in one drift before the state counts as runaway (the event
#: count of a drift grows with it; legitimate runs stay many orders of magnitude below).
MAX_CROSSINGS_PER_DRIFT = 1e9


def _refuse_runaway(particles: Particles, box: Box, dt: float) -> None:
    """Stop before an event-driven drift whose event count would be astronomical."""
    if particles.n == 0:
        return
    components = np.abs(particles.velocity).max(axis=1)
    fastest = int(np.argmax(components))
    speed = float(components[fastest])
    if speed * dt > MAX_CROSSINGS_PER_DRIFT * min(box.width, box.height):
        raise SimulationError(
            f"particle {fastest} moves at {speed:.3g} m/s, over {MAX_CROSSINGS_PER_DRIFT:.0g} box "
            "sides per step: the state has run away; try a smaller dt or softening"
        )


class _Stateless:
    """A mode whose drift depends on the particles alone (work arrays are rebuilt identically)."""

    def state(self) -> dict[str, np.ndarray]:
        """Nothing to save."""
        return {}

    def load_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Nothing to restore."""


class NoCollisions(_Stateless):
    """Pass-through: free flight with exact wall reflection (or periodic wrapping)."""

    def drift(
        self,
        particles: Particles,
        box: Box,
        now: float,
        dt: float,
        tally: Tally,
        acceleration: FloatArray | None = None,
    ) -> None:
        """Move ``particles`` from ``now`` to ``now + dt`` (s), in place."""
        _free_flight(particles, box, dt, tally)


class StepCollisions(_Stateless):
    """The seed's method: drift, fold back from walls, resolve overlapping pairs in index order.

    A collision is only detected if the disks overlap at the end of a step, so fast or small disks
    can pass through each other; energy is still conserved by each resolved collision.
    """

    def __init__(self) -> None:
        self._grid: _Grid | None = None
        self._pairs = np.empty(64, dtype=np.int64)

    def drift(
        self,
        particles: Particles,
        box: Box,
        now: float,
        dt: float,
        tally: Tally,
        acceleration: FloatArray | None = None,
    ) -> None:
        """Move ``particles`` from ``now`` to ``now + dt`` (s), in place."""
        _free_flight(particles, box, dt, tally)
        if self._grid is None or self._grid.cell_of.shape[0] != particles.n:
            self._grid = _Grid(particles, box)
        g = self._grid
        while True:
            count = stepper.overlapping_pairs(
                particles.position, particles.radius, box.width, box.height, *g.shape,
                g.cell_of, g.head, g.next, g.prev, g.cells, g.shifts, self._pairs,
            )  # fmt: skip
            if count <= self._pairs.shape[0]:
                break
            self._pairs = np.empty(2 * count, dtype=np.int64)
        tally.counts[0] += stepper.resolve_pairs(
            self._pairs[:count], particles.position, particles.velocity, particles.mass,
            box.width, box.height, box.periodic, tally.impulse,
        )  # fmt: skip


class ExactCollisions:
    """Event-driven drift: exact collision times and exact elastic responses.

    The engine keeps lazily updated positions of its own; ``particles.position`` receives the
    positions at the end of each drift. If the particles' positions or velocities differ from what
    the engine last wrote (a force kick, an edit by the user), the queue is rebuilt from them.
    """

    def __init__(self) -> None:
        self._state: dict[str, np.ndarray] | None = None
        self._written: FloatArray | None = None  # positions last written to the particles
        #: Events processed so far (collisions, wall hits, cell crossings, stale events).
        self.events = 0
        #: Times the event queue was built from scratch.
        self.rebuilds = 0

    def state(self) -> dict[str, np.ndarray]:
        """The event queue and lazily updated positions, and the event counters."""
        out: dict[str, np.ndarray] = {
            "events": np.array([self.events, self.rebuilds], dtype=np.int64)
        }
        if self._state is not None and self._written is not None:
            out |= {f"queue/{name}": array for name, array in self._state.items()}
            out["written"] = self._written
        return out

    def load_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Continue from a saved queue (or rebuild it at the next drift if none was saved)."""
        self.events, self.rebuilds = (int(x) for x in arrays["events"])
        queue = {k.removeprefix("queue/"): v for k, v in arrays.items() if k.startswith("queue/")}
        self._state = {name: np.array(array) for name, array in queue.items()} or None
        self._written = np.array(arrays["written"]) if "written" in arrays else None

    def _is_current(self, particles: Particles) -> bool:
        return (
            self._state is not None
            and self._written is not None
            and np.array_equal(self._written, particles.position)
            and np.array_equal(self._state["velocity"], particles.velocity)
            and np.array_equal(self._state["radius"], particles.radius)
        )

    def _rebuild(self, particles: Particles, box: Box, now: float) -> dict[str, np.ndarray]:
        n = particles.n
        grid = _Grid(particles, box)
        ncx, ncy = grid.shape
        s = {
            "position": particles.position.copy(),
            "velocity": particles.velocity.copy(),
            "radius": particles.radius.copy(),  # what the queue was predicted with
            "stamp": np.empty(n),
            "geometry": np.array(
                [0.5 * box.width, 0.5 * box.height, box.width / ncx, box.height / ncy]
            ),
            "grid": np.array([ncx, ncy, int(box.periodic)], dtype=np.int64),
            "cell_of": grid.cell_of, "head": grid.head, "next": grid.next, "prev": grid.prev,
            "cells": grid.cells, "shifts": grid.shifts,
            "collisions": np.zeros(n, dtype=np.int64),
            "event_time": np.empty(n),
            "event_kind": np.empty(n, dtype=np.int64),
            "event_other": np.empty(n, dtype=np.int64),
            "event_stamp": np.empty(n, dtype=np.int64),
            "heap": np.empty(n, dtype=np.int64),
            "heap_keys": np.empty(n),
            "heap_where": np.empty(n, dtype=np.int64),
        }  # fmt: skip
        events.rebuild(
            now, s["position"], s["velocity"], s["stamp"], particles.radius, s["geometry"],
            s["grid"], s["cell_of"], s["head"], s["next"], s["prev"], s["cells"], s["shifts"],
            s["collisions"], s["event_time"], s["event_kind"], s["event_other"],
            s["event_stamp"], s["heap"], s["heap_keys"], s["heap_where"],
        )  # fmt: skip
        return s

    def drift(
        self,
        particles: Particles,
        box: Box,
        now: float,
        dt: float,
        tally: Tally,
        acceleration: FloatArray | None = None,
    ) -> None:
        """Move ``particles`` from ``now`` to ``now + dt`` (s), in place."""
        _refuse_runaway(particles, box, dt)
        if not self._is_current(particles):
            self._state = self._rebuild(particles, box, now)
            self.rebuilds += 1
        s = self._state
        assert s is not None
        until = now + dt
        processed = events.run_events(
            until, s["position"], s["velocity"], s["stamp"], particles.mass, particles.radius,
            particles.image, s["geometry"], s["grid"], s["cell_of"], s["head"], s["next"],
            s["prev"], s["cells"], s["shifts"], s["collisions"], s["event_time"],
            s["event_kind"], s["event_other"], s["event_stamp"], s["heap"], s["heap_keys"],
            s["heap_where"], tally.counts, tally.impulse,
            _NO_ACCELERATION if acceleration is None else acceleration, now + 0.5 * dt,
        )  # fmt: skip
        if processed < 0:
            self._state = None  # the queue is unusable; a later drift rebuilds it
            stuck = -1 - processed
            raise SimulationError(
                f"particle {stuck}: time stopped advancing in the event-driven drift near "
                f"t = {until:.6g} s (velocity {s['velocity'][stuck].tolist()} m/s); "
                "the state has run away: try a smaller dt or softening"
            )
        self.events += processed
        events.synchronise(until, s["position"], s["velocity"], s["stamp"], particles.position)
        particles.velocity[...] = s["velocity"]
        self._written = particles.position.copy()
