"""Whole reporting intervals of the exact engine without forces, or under the uniform gravity
it carries, compiled.

Without forces that kick, the exact engine's queue lives on from step to step
(`collidium.kernels.events`), and a step of a small scene is a few microseconds of events inside
some twenty of Python: the drift's checks, the run loop, the audit. `event_intervals` takes many
steps in one call, each as `collidium.collisions.ExactCollisions.drift` and the run loop take one:
the events up to the step's end (`events.run_events`), the particles written at it
(`events.synchronise`) and audited (`collidium.kernels.audit.all_valid`), and it records what the
observers read at each step's end (`collidium.kernels.substeps.RECORD`, and the tallies), so that a
run flies the steps between the observers that read more of its state. It stops where the drift or
the run loop would do anything else: a speed that `collidium.collisions` refuses, a particle outside
the vessel or a value not finite, disks spread out of the cells' window, or time that stops
advancing.
"""

from __future__ import annotations

from collidium.kernels import events
from collidium.kernels.audit import all_valid, first_past_face
from collidium.kernels.compilation import uncounted
from collidium.kernels.floats import largest_magnitude
from collidium.kernels.sums import kinetic_energy, momentum, total_speed
from collidium.kernels.vessels import BOX
from collidium.kernels.vessels import piston as piston_kernels

#: How `event_intervals` ended: every interval taken; at an interval that the drift must take
#: (its speeds are refused, or the audit fails after it: the interval counts as taken then);
#: after an interval that left disks outside the cells' window (the queue must be built again).
ALL, STOPPED, OUT_OF_WINDOW = range(3)


@uncounted()
def event_intervals(
    origin, elapsed, dt, count, body, image, geometry, grid, head, next_, event, keys, items,
    tally, impulse, acceleration, sort_every, log, logged, walls, heat, segments, piston, position,
    velocity, mass, radius, fall_x, fall_y, width, height, reach, audit_shape, limit_x, limit_y,
    slack, periodic, window_is_vessel, piston_allowance, piston_now, record, counts, impulses,
    heats, wanted,
) -> tuple[int, int, int]:  # fmt: skip
    """Up to ``count`` steps of ``dt`` (s) of the exact engine without forces, or under the one
    uniform gravity it carries, in place.

    Step k runs from ``origin + (elapsed + k) dt`` (the simulation's clock) to the next.

    Parameters
    ----------
    origin, elapsed, dt, count
        The clock's origin (s), the steps from it to the first step's start, the step (s) and
        the most steps to take (at most ``len(record)``).
    body, image, geometry, grid, head, next_, event, keys, items, tally, impulse, acceleration,
    sort_every, log, logged, walls, heat, segments, piston
        As `events.run_events` takes them (``acceleration`` empty: nothing is logged).
    position, velocity : ndarray, shape (N, 2)
        The particles' state (m, m/s), written at each step's end (`events.synchronise`).
    mass, radius : ndarray, shape (N,)
        In kg and m.
    fall_x, fall_y : float
        The gravity the engine carries (``geometry``'s), m/s^2: its potential energy
        ``-sum m_i g . x_i`` is recorded (`collidium.forces.uniform`), with the unwrapped
        positions in a periodic box of sides ``width`` and ``height`` (m).
    reach : float
        A step is left to the drift when its largest velocity component (m/s), and what the
        fall adds over ``dt``, times ``dt`` is not within this distance (m;
        `collidium.collisions` refuses it then).
    audit_shape, limit_x, limit_y, slack, periodic
        The vessel as `collidium.kernels.audit.first_invalid` takes it (``segments`` too).
    window_is_vessel : bool
        Whether the cells' window covers the vessel (disks outside it are then no reason to
        build the queue again).
    piston_allowance : float
        How far past the ``piston``'s face (if any) a disk may reach, round-off (m;
        `collidium.vessels.Vessel.piston_face`): the audit tests it after each step.
    piston_now : ndarray, shape (2,)
        Output, with a piston: its face's position and velocity along its axis at the last
        step's end (m, m/s), as `collidium.collisions.Tally.piston` keeps them.
    record : ndarray, shape (count, len(RECORD))
        Output: `collidium.kernels.substeps.RECORD` at the end of each step ``wanted`` (no pair
        virial: 0); the other rows are left as they are.
    counts, impulses, heats : ndarray, shape (count, 1 + W)
        Output: ``tally``, ``impulse`` and ``heat`` at each step's end.
    wanted : ndarray of bool, shape (count,)
        The steps whose ``record`` an observer reads.

    Returns
    -------
    tuple of int
        ``(steps taken, events processed, how it ended)``: `ALL`, `STOPPED`, `OUT_OF_WINDOW`,
        or ``-1 - i`` if time stopped advancing at particle i in a later step (`events.run_events`;
        the steps taken are then those whose end the particles hold, and the tallies hold part
        of the steps after them).

    In a box without segments or a piston the particles are written only at the steps an
    observer reads, at the last and where a step stops the flight: the others are audited from
    the slots (`events.audit_in_box`, the same verdicts), which spares the scattered writes
    (0.8 of the 1.4 us a step of a 200-disk gas spent outside its events).
    """
    processed = 0
    falls = fall_x != 0.0 or fall_y != 0.0
    in_box = audit_shape == BOX and segments.shape[0] == 0 and piston.shape[0] == 0
    largest = largest_magnitude(velocity)
    written, written_events, last = 0, 0, origin  # the steps whose end the particles hold
    for k in range(count):
        now = origin + (elapsed + k) * dt
        speed = largest + max(abs(fall_x), abs(fall_y)) * dt
        if not speed * dt <= reach:  # also NaN
            if written < k:
                events.synchronise(last, body, event, geometry, grid, position, velocity)
            return k, processed, STOPPED
        until = now + dt
        done = events.run_events(until, body, image, geometry, grid, head, next_, event, keys,
                                 items, tally, impulse, acceleration, now + 0.5 * dt,
                                 sort_every, log, logged, walls, heat, segments,
                                 piston)  # fmt: skip
        if done < 0:
            return written, written_events, done
        processed += done
        _tallies(k, tally, impulse, heat, counts, impulses, heats)
        last = until
        if in_box and not wanted[k] and k < count - 1:
            valid, strays, largest = events.audit_in_box(until, body, geometry, grid, limit_x,
                                                         limit_y, periodic,
                                                         window_is_vessel)  # fmt: skip
            if valid and strays == 0:  # none counted where the window is the vessel
                continue
        strays = events.synchronise(until, body, event, geometry, grid, position, velocity)
        written, written_events = k + 1, processed
        largest = largest_magnitude(velocity)
        if wanted[k]:
            _record(k, mass, velocity, record)
            if falls:
                record[k, 1] = 0.0 + _fall_energy(position, image, mass, fall_x, fall_y,
                                                  periodic, width, height)  # fmt: skip
        invalid = not all_valid(position, velocity, radius, audit_shape, limit_x, limit_y,
                                slack, periodic, segments)  # fmt: skip
        if piston.shape[0] > 0:
            invalid = _piston_at(piston, until, position, radius, piston_allowance,
                                 piston_now) or invalid  # fmt: skip
        if invalid:
            return k + 1, processed, STOPPED
        if strays > 0 and not window_is_vessel:
            return k + 1, processed, OUT_OF_WINDOW
    return count, processed, ALL


@uncounted()
def _piston_at(piston, t, position, radius, allowance, now) -> bool:
    """The piston's face at time t (s) into ``now`` (2,) (position and velocity along its axis,
    as `collidium.collisions.Tally.piston`); whether a disk reaches past it by more than the
    ``allowance`` (m; `collidium.kernels.audit.first_past_face`)."""
    height, speed = piston_kernels.motion(piston, t)
    wall = int(piston[piston_kernels.WALL])
    sign = 1.0 if wall % 2 == 1 else -1.0
    now[0] = sign * height
    now[1] = sign * speed
    return first_past_face(position, radius, wall // 2, sign, now[0], allowance) >= 0


@uncounted()
def _record(k, mass, velocity, record) -> None:
    """Row k of `collidium.kernels.substeps.RECORD`, without forces."""
    px, py = momentum(mass, velocity)
    record[k, 0] = kinetic_energy(mass, velocity)
    record[k, 1] = 0.0
    record[k, 2] = 0.0
    record[k, 3] = px
    record[k, 4] = py
    record[k, 5] = total_speed(velocity)


@uncounted()
def _tallies(k, tally, impulse, heat, counts, impulses, heats) -> None:
    """Row k of the tallies' records."""
    for w in range(tally.shape[0]):
        counts[k, w] = tally[w]
        impulses[k, w] = impulse[w]
        heats[k, w] = heat[w]


@uncounted()
def _fall_energy(position, image, mass, fall_x, fall_y, periodic, width, height) -> float:
    """``-sum m_i g . x_i`` (J) in particle order, as `collidium.forces.uniform` gives each
    particle's and `collidium.kernels.sums.ordered_sum` adds them: the unwrapped position in a
    periodic box."""
    total = 0.0
    for i in range(position.shape[0]):
        x, y = position[i, 0], position[i, 1]
        if periodic:
            x = x + image[i, 0] * width
            y = y + image[i, 1] * height
        total += -(x * (mass[i] * fall_x) + y * (mass[i] * fall_y))
    return total
