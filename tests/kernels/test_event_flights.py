"""The exact engine's compiled steps without forces (`event_flights`) against the twin, and where
they stop."""

from __future__ import annotations

import numpy as np
import pytest

from collidium import Box, Circle, Gravity, Particles, Simulation, collisions
from collidium.collisions import ExactCollisions, FlightRecord
from collidium.kernels import event_flights, reference
from lattices import jittered_lattice

STEPS = 7


def _gas(
    rng: np.random.Generator, vessel: Box | Circle, side: float, fall: float = 0.0
) -> Simulation:
    """A gas of unequal disks, falling with ``fall`` m/s^2 (down), its queue built by a first
    step."""
    position = jittered_lattice(8, side, 0.4, rng)
    n = len(position)
    velocity = rng.uniform(-10, 10, (n, 2))
    mass, radius = rng.uniform(0.5, 2.0, n), rng.uniform(0.1, 0.4, n)
    particles = Particles(position, velocity, mass=mass, radius=radius)
    forces = [Gravity((0.0, -fall))] if fall else []
    return Simulation(vessel, particles, forces=forces, dt=0.1).run(steps=1)


def _fly(sim: Simulation, steps: int = STEPS, read: bool = True) -> tuple[int, FlightRecord]:
    """Steps flown in one call, each ``read`` by an observer or none."""
    drift = sim._drift
    assert isinstance(drift, ExactCollisions)
    record = FlightRecord.empty(sim.tally, np.full(steps, read))
    origin, start = sim._time_origin
    flown = drift.fly(sim.particles, sim.container, origin, sim.steps - start, sim.dt, sim.tally,
                      record, sim._field.fall)  # fmt: skip
    return flown, record


@pytest.mark.parametrize(("shape", "fall"), [("box", 0.0), ("circle", 0.0), ("box", 5.0)])
def test_flown_steps_match_the_twin(rng, shape, fall):
    """Steps flown in one call end as the all-pairs twin's steps do, and record at each end the
    same energies (of a gravity the engine carries too), momentum, total speed, counts and
    impulses, to the round-off growth of a chaotic gas (`tests/kernels/test_events.py`)."""
    vessel = Box(20.0, 20.0) if shape == "box" else Circle(10.0)
    sim = _gas(rng, vessel, 20.0 if shape == "box" else 13.0, fall)
    p = sim.particles
    position, velocity = p.position.copy(), p.velocity.copy()
    tally = sim.tally.counts.copy(), sim.tally.impulse.copy()
    flown, record = _fly(sim)
    half = np.array([10.0, 10.0])
    values, counts, impulses = reference.event_intervals(
        position, velocity, p.mass, p.radius, half, sim.dt, STEPS,
        rim=10.0 if shape == "circle" else None, fall=np.array([0.0, -fall]),
    )  # fmt: skip
    assert flown == STEPS
    assert counts[-1, 0] > 5 and counts[-1, 1] > 5
    pairs, walls = record.counts[:, 0], record.counts[:, 1:].sum(axis=1)
    np.testing.assert_array_equal(pairs, tally[0][0] + counts[:, 0])
    np.testing.assert_array_equal(walls, tally[0][1:].sum() + counts[:, 1])
    np.testing.assert_allclose(record.impulse, tally[1] + impulses, rtol=1e-9)
    np.testing.assert_allclose(record.values, values, rtol=1e-9, atol=1e-9 * values[0, 0])
    assert (record.values[:, 1] != 0.0).all() == bool(fall)
    np.testing.assert_allclose(p.position, position, rtol=0, atol=1e-9 * 10.0)
    np.testing.assert_allclose(p.velocity, velocity, rtol=0, atol=1e-8 * 10)
    np.testing.assert_array_equal(record.heat, 0.0)


def test_a_refused_speed_stops_before_the_step(rng, monkeypatch):
    """A step whose speeds the drift would refuse is left to the drift, untouched."""
    sim = _gas(rng, Box(20.0, 20.0), 20.0)
    position, counts = sim.particles.position.copy(), sim.tally.counts.copy()
    monkeypatch.setattr(collisions, "_runaway_reach", lambda vessel: 1e-3)
    flown, _ = _fly(sim)
    assert flown == 0
    np.testing.assert_array_equal(sim.particles.position, position)
    np.testing.assert_array_equal(sim.tally.counts, counts)


def test_time_that_stops_advancing_puts_the_tallies_back(rng, monkeypatch):
    """A step at which time stops advancing (a runaway state) is left to the drift, which says
    where it stopped: the flight puts back what the step added to the tallies and drops the
    queue, so that the drift builds it again from the particles the last step wrote."""
    sim = _gas(rng, Box(20.0, 20.0), 20.0)
    kernel = event_flights.event_intervals

    def stuck_in_the_third(*args):
        flown, processed, _ = kernel(*args[:3], 2, *args[4:])
        tally = args[13]
        tally += 5  # part of the third step, counted
        return flown, processed, -1 - 4

    monkeypatch.setattr(event_flights, "event_intervals", stuck_in_the_third)
    flown, record = _fly(sim)
    assert flown == 2
    np.testing.assert_array_equal(sim.tally.counts, record.counts[1])
    assert sim._drift._state is None


def test_a_failed_audit_ends_the_flight_after_its_step(rng, monkeypatch):
    """A step that leaves a disk outside the vessel (here a vessel made smaller for the audit
    alone) is taken and ends the flight, for the run loop's audit to report."""
    sim = _gas(rng, Box(20.0, 20.0), 20.0)
    code, _, _, slack, periodic = sim.container.audit_arguments()
    # The disks reach further out at some step of the next seven than they do now.
    now = float(np.max(np.abs(sim.particles.position) + sim.particles.radius[:, None]))
    monkeypatch.setattr(Box, "audit_arguments", lambda self: (code, now, now, slack, periodic))
    flown, _ = _fly(sim)
    assert 1 <= flown < STEPS
    assert np.max(np.abs(sim.particles.position) + sim.particles.radius[:, None]) > now


def _outcome(sim: Simulation, flown: int, record: FlightRecord) -> tuple[np.ndarray, ...]:
    """The particles, the tallies and the counts recorded at the steps flown."""
    p = sim.particles
    return p.position, p.velocity, sim.tally.counts, sim.tally.impulse, record.counts[:flown]


def test_steps_no_observer_reads_give_the_bits_of_steps_read(rng):
    """Steps that no observer reads are audited from the engine's slots, the particles written
    at the last (`events.audit_in_box`): the same particles, tallies and counts, bit for bit, as
    steps that write them at each end."""
    runs = []
    for read in (True, False):
        sim = _gas(np.random.default_rng(8), Box(20.0, 20.0), 20.0)
        flown, record = _fly(sim, read=read)
        assert flown == STEPS
        runs.append(_outcome(sim, flown, record))
    assert runs[0][4][-1, 0] > 5
    for a, b in zip(*runs, strict=True):
        np.testing.assert_array_equal(a, b)


def test_an_unread_step_that_fails_the_audit_ends_the_flight_after_it(monkeypatch):
    """The audit from the slots fails at the step the particles' audit fails at: the flight
    ends after it, the particles written there, as when every step is read."""
    code, _, _, slack, periodic = Box(20.0, 20.0).audit_arguments()
    runs = []
    for read in (True, False):
        sim = _gas(np.random.default_rng(9), Box(20.0, 20.0), 20.0)
        now = float(np.max(np.abs(sim.particles.position) + sim.particles.radius[:, None]))
        with monkeypatch.context() as patch:
            patch.setattr(Box, "audit_arguments", lambda self, now=now: (code, now, now, slack,
                                                                         periodic))  # fmt: skip
            flown, record = _fly(sim, read=read)
        assert 1 <= flown < STEPS - 1
        runs.append((flown, *_outcome(sim, flown, record)))
    assert runs[0][0] == runs[1][0]
    for a, b in zip(runs[0][1:], runs[1][1:], strict=True):
        np.testing.assert_array_equal(a, b)
