"""The compiled substeps that meet no contact against their NumPy twin, and where they stop
when no engine takes their contacts (those that do are run against the Python path in
``tests/test_integrators.py``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collidium import Box, Polygon
from collidium.collisions import SubstepEngine
from collidium.kernels import reference, substeps
from collidium.kernels.substeps import CONTACT_MARGIN, RECORD, needed
from collidium.kernels.sums import kinetic_energy
from collidium.kernels.vessels import BOX, CIRCLE, POLYGON


def no_engine() -> tuple[object, ...]:
    """``contacts`` without an engine (`SubstepEngine.disabled`), and a box's tallies."""
    engine = SubstepEngine.disabled(Box(10, 10))
    tally = (np.zeros(5, dtype=np.int64), np.zeros(5), np.zeros(5))
    return (engine.queue, engine.walls, engine.sort_every, engine.reach, engine.log.rows,
            engine.log.count, np.zeros((1, 2), dtype=np.int64), *tally)  # fmt: skip


def smooth_substeps(*arguments, tolerance=math.inf):
    """`substeps.smooth_substeps` without an engine: ``(substep, time, fastest, given)``; with
    an infinite ``tolerance`` the rate is read at every substep and never stops them."""
    return substeps.smooth_substeps(*arguments, tolerance, MOST, no_engine())[:4]


def smooth_intervals(*arguments):
    """`substeps.smooth_intervals` without an engine: ``(intervals, next count)``."""
    count = arguments[21]
    tallies = (np.empty((count, 5), dtype=np.int64), np.empty((count, 5)), np.empty((count, 5)))
    shown = (False, np.zeros(count, dtype=bool), (0.0, 0.0, 0.0))  # the record of the state
    return substeps.smooth_intervals(*arguments, no_engine(), *tallies, *shown)[:2]


FLOOR = 10.0
NONE = np.empty((0, 9))
WHOLE = np.array([-np.inf, -np.inf, np.inf, np.inf])
#: No uniform field and no velocity force (`smooth_substeps`'s ``uniform, fall, turn, region,
#: damp``).
FREE = (np.empty((0, 2)), np.empty(0), np.empty(0), WHOLE, np.empty(0))
HEXAGON = Polygon([[6.0 * np.cos(a), 6.0 * np.sin(a)] for a in np.arange(6) * np.pi / 3])


def scene(rng, n, spread=3.0, speed=1.0):
    """Disks of radius 0.1 on a jittered ring (none touching), random masses and charges of both
    signs (some neutral), with k = 5 and a softening of 0.1 m."""
    angle = np.arange(n) * 2 * np.pi / n
    position = spread * np.column_stack([np.cos(angle), np.sin(angle)])
    position += rng.uniform(-0.2, 0.2, position.shape)
    velocity = rng.normal(0.0, speed, (n, 2))
    mass = rng.uniform(0.5, 2.0, n)
    radius = np.full(n, 0.1)
    charge = rng.choice([-1.0, 0.0, 1.0], n)
    return position, velocity, mass, radius, charge, 5.0, 0.01


def accelerations(position, mass, source, coupling, softening2):
    return (
        reference.inverse_distance_direct(position, source, coupling, softening2)[0] / mass[:, None]
    )


def energy(position, source, coupling, softening2):
    return float(reference.inverse_distance_direct(position, source, coupling, softening2)[1].sum())


WALLS = {
    "box": (BOX, np.array([5.0, 5.0]), np.nan, NONE),
    "circle": (CIRCLE, np.array([5.0, 5.0]), 5.0, NONE),
    "hexagon": (POLYGON, 0.5 * HEXAGON.extent, np.nan, HEXAGON.segments()),
}


@pytest.mark.parametrize("vessel", WALLS)
@pytest.mark.parametrize("speed", [0.5, 40.0])
def test_substeps_equal_their_twin(rng, vessel, speed):
    """Slow disks take every substep of 0.1 s; fast ones, 4 m in it, stop where the twin
    stops, at a wall or a pair."""
    shape, half, rim, table = WALLS[vessel]
    position, velocity, mass, radius, source, coupling, softening2 = scene(rng, 12, speed=speed)
    acceleration = accelerations(position, mass, source, coupling, softening2)
    total = kinetic_energy(mass, velocity) + energy(position, source, coupling, softening2)
    got = [a.copy() for a in (position, velocity, acceleration)]
    want = [a.copy() for a in (position, velocity, acceleration)]
    step, t, fastest, _ = smooth_substeps(*got, mass, radius, source, coupling, softening2, *FREE,
                                       shape, half[0], half[1], rim, table, 1.0, 0.1, 1, 16, 1.0,
                                       0.0, total, FLOOR)  # fmt: skip
    twin = reference.smooth_substeps(*want, mass, radius, source, coupling, softening2, *FREE,
                                     shape, half, rim, table, 1.0, 0.1, 1, 16, 1.0, 0.0, total,
                                     FLOOR, CONTACT_MARGIN)  # fmt: skip
    assert (step, t) == twin[:2]
    assert (step == 17) == (speed < 1.0)
    assert step > 1 or speed > 1.0  # the fast disks too take some substeps first
    np.testing.assert_allclose(fastest, twin[2], rtol=1e-12)
    for ours, theirs in zip(got, want, strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-12)


def fields(mass, charge, kind):
    """The fields of a box, as `smooth_substeps` takes them (``uniform, fall, turn, region,
    damp``): an ``"electric"`` field E = (0.3, -0.8) N/C with a magnetic field of 2 T in the
    left half of the box (x < 0); or a ``"falling"`` gravity g = (0, -3) m/s^2 that the drift
    carries, with a linear drag of gamma = 0.7 kg/s."""
    if kind == "electric":
        uniform = charge[:, None] * np.array([0.3, -0.8])
        left = np.array([-np.inf, -np.inf, 0.0, np.inf])
        return uniform, np.empty(0), 2.0 * charge / mass, left, np.empty(0)
    g = np.array([0.0, -3.0])
    return mass[:, None] * g, g, np.empty(0), WHOLE, 0.7 / mass


def pulled(position, mass, source, coupling, softening2, external):
    """The accelerations and the total energy of a scene under ``external`` fields (`fields`):
    the uniform field in the accelerations unless the drift carries it."""
    uniform, fall = external[:2]
    acceleration = accelerations(position, mass, source, coupling, softening2)
    if not fall.size:
        acceleration = acceleration + uniform / mass[:, None]
    return acceleration, energy(position, source, coupling, softening2) - np.sum(position * uniform)


@pytest.mark.parametrize("kind", ["electric", "falling"])
@pytest.mark.parametrize("pair", [True, False])
def test_substeps_under_fields_equal_their_twin(rng, pair, kind):
    """Charges with (or without) their Coulomb pairs under a uniform electric field and a
    magnetic field over half the box, or under a carried gravity and drag: the same substeps as
    the twin's; the motion, the rate (the velocity forces' fastest rate squared where it is the
    larger) and the energy the drag took, to round-off."""
    position, velocity, mass, radius, charge, coupling, softening2 = scene(rng, 12, speed=2.0)
    external = fields(mass, charge, kind)
    source = charge if pair else np.zeros_like(charge)
    acceleration, potential = pulled(position, mass, source, coupling, softening2, external)
    total = kinetic_energy(mass, velocity) + potential
    got = [a.copy() for a in (position, velocity, acceleration)]
    want = [a.copy() for a in (position, velocity, acceleration)]
    shape, half, rim, table = WALLS["box"]
    step, t, fastest, given = smooth_substeps(*got, mass, radius, source, coupling, softening2,
                                              *external, shape, half[0], half[1], rim, table,
                                              1.0, 0.5, 1, 32, 1.0, 0.0, total,
                                              FLOOR)  # fmt: skip
    twin = reference.smooth_substeps(*want, mass, radius, source, coupling, softening2,
                                     *external, shape, half, rim, table, 1.0, 0.5, 1, 32, 1.0,
                                     0.0, total, FLOOR, CONTACT_MARGIN)  # fmt: skip
    assert (step, t) == twin[:2]
    assert step > 4  # some substeps taken before a contact, if any
    np.testing.assert_allclose(fastest, twin[2], rtol=1e-12)
    if not pair:
        rates = external[2] if kind == "electric" else external[4]
        assert fastest == np.max(np.abs(rates)) ** 2
    np.testing.assert_allclose(given, twin[3], rtol=1e-12)
    assert (given < 0.0) == (kind == "falling")
    for ours, theirs in zip(got, want, strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-12)


def test_a_magnetic_field_turns_a_charge_without_changing_its_speed():
    """A free charge in a field filling the plane circles at its cyclotron frequency: after
    substeps making half a period it has turned its velocity round, to O((omega h)^2), with
    its speed kept to round-off."""
    position = np.array([[0.0, -1.0]])
    velocity = np.array([[1.0, 0.0]])
    mass = np.ones(1)
    omega = 1.0  # q B / m: clockwise, on the circle of radius 1 about (0, -2)
    args = (np.zeros((1, 2)), mass, np.full(1, 0.1), np.zeros(1), 0.0, 0.0, np.empty((0, 2)),
            np.empty(0), np.full(1, omega), WHOLE, np.empty(0), BOX, 5.0, 5.0, np.nan, NONE,
            0.0, np.pi, 1, 256, 0.0, 0.0, 0.5, FLOOR)  # fmt: skip
    step, t, fastest, given = smooth_substeps(position, velocity, *args)
    assert (step, fastest, given) == (257, omega**2, 0.0)
    assert t == pytest.approx(np.pi, rel=1e-15)
    np.testing.assert_allclose(velocity[0], [-1.0, 0.0], atol=(np.pi / 256) ** 2)
    assert np.hypot(*velocity[0]) == pytest.approx(1.0, rel=1e-14)
    np.testing.assert_allclose(position[0], [0.0, -3.0], atol=(np.pi / 256) ** 2)


def test_a_disk_falling_through_a_fluid_reaches_its_terminal_velocity():
    """A disk of 2 kg dropped from rest under g = 1 m/s^2 with linear drag gamma = 1 kg/s: its
    velocity after 6 time constants is ``-m g / gamma (1 - exp(-6))`` to O(h^2), and the
    energy the drag took is what the fall gave less what the disk keeps."""
    position, velocity = np.array([[0.0, 15.0]]), np.zeros((1, 2))
    mass, g = np.array([2.0]), np.array([0.0, -1.0])
    h = 12.0 / 1024
    args = (np.zeros((1, 2)), mass, np.full(1, 0.1), np.zeros(1), 0.0, 0.0, mass[:, None] * g,
            g, np.empty(0), WHOLE, 1.0 / mass, BOX, 5.0, 50.0, np.nan, NONE, 0.0, 12.0, 1,
            1024, 0.0, 0.0, 1.0, FLOOR)  # fmt: skip
    step, _, fastest, given = smooth_substeps(position, velocity, *args)
    assert (step, fastest) == (1025, 0.25)
    terminal = -2.0 * (1.0 - np.exp(-6.0))
    np.testing.assert_allclose(velocity[0], [0.0, terminal], atol=h**2)
    fallen = 15.0 - position[0, 1]
    kept = 0.5 * 2.0 * velocity[0, 1] ** 2
    assert given == pytest.approx(kept - 2.0 * 1.0 * fallen, rel=1e-12)


def test_a_crowd_stops_where_its_all_pairs_twin_stops(rng):
    """49 neutral disks of radii 0.05 to 0.3 m on a jittered grid, in random motion, the pair
    test pruned along x (disks pass each other in x from substep to substep, re-sorting the
    sweep): in each of 40 crowds the substeps stop where the twin's test of every pair stops
    them, at a pair (the walls are 20 m away)."""
    grid = 1.1 * np.stack(np.meshgrid(np.arange(7), np.arange(7)), axis=-1).reshape(-1, 2) - 3.3
    steps = []
    for _ in range(40):
        n = grid.shape[0]
        position = grid + rng.uniform(-0.2, 0.2, grid.shape)  # gaps of 0.1 m at least
        radius = rng.uniform(0.05, 0.3, n)
        velocity = rng.normal(0.0, 1.0, (n, 2))
        args = (np.zeros((n, 2)), np.ones(n), radius, np.zeros(n), 5.0, 0.0, *FREE, BOX)
        got, want = (position.copy(), velocity.copy()), (position.copy(), velocity.copy())
        step, t, _, _ = smooth_substeps(*got, *args, 20.0, 20.0, np.nan, NONE, 0.0, 2.0, 1, 64, 0.0,
                                     0.0, 1.0, FLOOR)  # fmt: skip
        twin = reference.smooth_substeps(*want, *args, np.array([20.0, 20.0]), np.nan, NONE, 0.0,
                                         2.0, 1, 64, 0.0, 0.0, 1.0, FLOOR,
                                         CONTACT_MARGIN)  # fmt: skip
        assert (step, t) == twin[:2]
        np.testing.assert_allclose(got[0], want[0], rtol=1e-12, atol=1e-12)
        steps.append(step)
    assert max(steps) <= 64  # every crowd met a pair within 2 s
    assert np.median(steps) >= 3  # most after some substeps of sweeping


def test_a_disk_bound_for_a_wall_stops_the_substeps_just_before_it():
    """A neutral disk at 10 m/s, 1 m from a wall: substeps of 0.01 s take it to 0.1 m short
    and stop before the one that would reach it; nothing of that substep is kept."""
    position = np.array([[3.9, 0.0], [-3.0, 0.0]])
    velocity = np.array([[10.0, 0.0], [0.0, 0.0]])
    acceleration = np.zeros((2, 2))
    mass, radius = np.ones(2), np.array([0.1, 0.1])
    step, t, _, _ = smooth_substeps(position, velocity, acceleration, mass, radius, np.zeros(2),
                                    5.0, 0.0, *FREE, BOX, 5.0, 5.0, np.nan, NONE, 0.0, 0.16, 1,
                                    16, 0.0, 0.0, 50.0, FLOOR)  # fmt: skip
    # The wall's contact is at x = 4.9, 0.1 s on: substeps 1 to 9 end at 0.09 s.
    assert (step, t) == (10, pytest.approx(0.09, rel=1e-15))
    np.testing.assert_allclose(position[0], [3.9 + 0.9, 0.0], rtol=1e-14)
    np.testing.assert_array_equal(velocity[0], [10.0, 0.0])


@pytest.mark.parametrize("miss", [0.5 * CONTACT_MARGIN, 2 * CONTACT_MARGIN])
def test_a_grazing_pair_stops_the_substeps_within_the_margin(miss):
    """Two disks that pass at a distance ``(1 + miss) sigma``: within the margin they stop the
    substeps, beyond it they fly on."""
    sigma = 0.2
    position = np.array([[-1.0, 0.5 * sigma * (1 + miss)], [1.0, -0.5 * sigma * (1 + miss)]])
    velocity = np.array([[5.0, 0.0], [-5.0, 0.0]])
    args = (np.zeros((2, 2)), np.ones(2), np.full(2, 0.5 * sigma), np.zeros(2), 5.0, 0.0, *FREE,
            BOX, 5.0, 5.0, np.nan, NONE, 0.0, 0.4, 1, 4, 0.0, 0.0, 25.0, FLOOR)  # fmt: skip
    step, _, _, _ = smooth_substeps(position, velocity, *args)
    assert step == (5 if miss > CONTACT_MARGIN else 2)  # they meet in the second 0.1 s


def test_infinite_accelerations_stop_the_substeps_with_nothing_changed():
    """A charge of 1e-310 kg beside another: the first substep's accelerations are infinite,
    so it is left to the integrator, which names the particle."""
    position = np.array([[-1.0, 0.0], [1.0, 0.0]])
    velocity = np.zeros((2, 2))
    acceleration = np.zeros((2, 2))
    before = position.copy()
    step, t, fastest, _ = smooth_substeps(position, velocity, acceleration, np.array([1e-310, 1.0]),
                                       np.zeros(2), np.ones(2), 5.0, 0.0, *FREE, BOX, 5.0, 5.0,
                                       np.nan, NONE, 0.0, 0.1, 1, 4, 0.0, 0.0, 2.5,
                                       FLOOR)  # fmt: skip
    assert (step, t, fastest) == (1, 0.0, 0.0)
    np.testing.assert_array_equal(position, before)
    np.testing.assert_array_equal(velocity, 0.0)


def test_kinetic_energy_is_half_m_v_squared(rng):
    mass = rng.uniform(0.5, 2.0, 50)
    velocity = rng.normal(0.0, 3.0, (50, 2))
    want = 0.5 * np.sum(mass * np.sum(velocity**2, axis=1))
    assert kinetic_energy(mass, velocity) == pytest.approx(want, rel=1e-14)


TOLERANCE = 0.01
MOST = 2**14


def three_bodies():
    """A heavy +2 C at the centre of a 10 m box, two light -1 C circling it at 1 and 2 m, with
    k = 5: their orbits stay clear of each other and of the walls."""
    position = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, -2.0]])
    velocity = np.array([[0.0, 0.0], [0.0, 3.1], [2.2, 0.0]])
    mass = np.array([100.0, 1.0, 1.0])
    charge = np.array([2.0, -1.0, -1.0])
    return position, velocity, mass, np.full(3, 0.05), charge


@pytest.mark.parametrize("tolerance", [1.0 / 64, 1.0 / 256])
def test_substeps_read_the_rate_every_stride_and_stop_where_it_needs_more(tolerance):
    """At a finite tolerance the rate is read every `rate_stride` substeps (2 and 8 here) and
    at the last, as the twin reads it: too few substeps stop at the first read, which needs
    more; enough go to the interval's end, the largest rate read the twin's."""
    position, velocity, mass, radius, charge = three_bodies()
    acceleration = accelerations(position, mass, charge, 5.0, 0.0)
    total = kinetic_energy(mass, velocity) + energy(position, charge, 5.0, 0.0)
    stride = substeps.rate_stride(tolerance)
    assert stride == reference.rate_stride(tolerance) == (2 if tolerance > 0.01 else 8)
    for count in (stride, 2048):
        got = [a.copy() for a in (position, velocity, acceleration)]
        want = [a.copy() for a in (position, velocity, acceleration)]
        step, t, fastest, _ = smooth_substeps(*got, mass, radius, charge, 5.0, 0.0, *FREE, BOX,
                                              5.0, 5.0, np.nan, NONE, 0.0, 0.5, 1, 4 * count,
                                              0.0, -1.0, total, FLOOR,
                                              tolerance=tolerance)  # fmt: skip
        twin = reference.smooth_substeps(*want, mass, radius, charge, 5.0, 0.0, *FREE, BOX,
                                         np.array([5.0, 5.0]), np.nan, NONE, 0.0, 0.5, 1,
                                         4 * count, 0.0, -1.0, total, FLOOR, CONTACT_MARGIN,
                                         tolerance, MOST)  # fmt: skip
        enough = needed(fastest, 0.5, tolerance, MOST) <= 4 * count
        assert enough == (count > stride)
        assert step == twin[0] == 4 * count + 1
        assert t == twin[1] == pytest.approx(0.5 if enough else 0.5 * stride / (4 * count))
        np.testing.assert_allclose(fastest, twin[2], rtol=1e-12)
        for ours, theirs in zip(got, want, strict=True):
            np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("count", [1, 40])
def test_intervals_equal_their_twin(count):
    """Intervals of 0.05 s of two light charges circling a heavy one: the same intervals taken,
    substep counts, energies, virials, momenta and speeds as the twin's, the motion to
    round-off."""
    position, velocity, mass, radius, charge = three_bodies()
    acceleration = accelerations(position, mass, charge, 5.0, 0.0)
    got = [a.copy() for a in (position, velocity, acceleration)]
    want = [a.copy() for a in (position, velocity, acceleration)]
    record = np.empty((count, len(RECORD)))
    flown, after = smooth_intervals(*got, mass, radius, charge, 5.0, 0.0, *FREE, BOX, 5.0, 5.0,
                                    np.nan, NONE, 0.0, 0, 0.05, count, 1, np.nan, True, TOLERANCE,
                                    MOST, FLOOR, 0.0, record, np.empty(count))  # fmt: skip
    twin = reference.smooth_intervals(*want, mass, radius, charge, 5.0, 0.0, *FREE, BOX,
                                      np.array([5.0, 5.0]), np.nan, NONE, 0.0, 0, 0.05, count, 1,
                                      TOLERANCE, MOST, FLOOR, 0.0, CONTACT_MARGIN,
                                      keep=True)  # fmt: skip
    assert (flown, after) == (count, twin[1]) and twin[0] == count
    assert after >= 8  # the inner orbit needs substeps
    if count > 1:  # the substep changed on the way, and the modified energy was kept
        plain = [a.copy() for a in (position, velocity, acceleration)]
        smooth_intervals(*plain, mass, radius, charge, 5.0, 0.0, *FREE, BOX, 5.0, 5.0, np.nan,
                         NONE, 0.0, 0, 0.05, count, 1, np.nan, False, TOLERANCE, MOST, FLOOR, 0.0,
                         np.empty((count, len(RECORD))), np.empty(count))  # fmt: skip
        assert not np.array_equal(plain[1], got[1])
    np.testing.assert_allclose(record, twin[2][:, :-1], rtol=1e-11, atol=1e-12)
    for ours, theirs in zip(got, want, strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=1e-10, atol=1e-12)


def test_a_wanted_interval_records_the_processed_state():
    """Three intervals shown processed, the last one's record wanted: it holds the energies,
    virial, momentum and total speed of the processed state of the motion there (its NumPy
    twin, `reference.processed_state`, of the last substep); the other rows and the motion
    itself are those of the intervals taken without the processing, bit for bit."""
    position, velocity, mass, radius, charge = three_bodies()
    acceleration = accelerations(position, mass, charge, 5.0, 0.0)
    runs = []
    for shows in (False, True):
        state = [a.copy() for a in (position, velocity, acceleration)]
        record = np.empty((3, len(RECORD)))
        tallies = (np.empty((3, 5), dtype=np.int64), np.empty((3, 5)), np.empty((3, 5)))
        _, _, substep, _, _ = substeps.smooth_intervals(
            *state, mass, radius, charge, 5.0, 0.0, *FREE, BOX, 5.0, 5.0, np.nan, NONE, 0.0, 0,
            0.05, 3, 1, np.nan, True, TOLERANCE, MOST, FLOOR, 0.0, record, np.empty(3),
            no_engine(), *tallies, shows, np.array([False, False, True]),
            Box(10, 10).audit_arguments()[1:4],
        )  # fmt: skip
        runs.append((state, record, substep))
    (plain, plain_record, substep), (state, record, _) = runs
    for ours, theirs in zip(state, plain, strict=True):
        np.testing.assert_array_equal(ours, theirs)
    np.testing.assert_array_equal(record[:2], plain_record[:2])
    laws = (charge[None, :], np.array([5.0]), np.array([0.0]))
    curved = reference.curved_velocities(state[0], state[1], laws)
    walls = (BOX, *Box(10, 10).audit_arguments()[1:4], NONE)
    x, v, _ = reference.processed_state(*state[:3], mass, curved, substep**2 / 12, radius, walls)
    assert not np.array_equal(x, state[0])
    _, halves, virials = reference.inverse_distance_direct(x, charge, 5.0, 0.0)
    speed = float(np.sum(np.hypot(v[:, 0], v[:, 1])))
    want = [kinetic_energy(mass, v), halves.sum(), virials.sum(), *(mass @ v), speed]
    np.testing.assert_allclose(record[2], want, rtol=1e-12)


@pytest.mark.parametrize("kind", ["electric", "falling"])
def test_intervals_under_fields_equal_their_twin(kind):
    """The three bodies under a uniform electric field and a magnetic field over half the box,
    or under a carried gravity and drag: the record's potential has the field's ``-F . x``
    too, and the energy the drag has given is kept interval by interval, as the twin's."""
    position, velocity, mass, radius, charge = three_bodies()
    external = fields(mass, charge, kind)
    acceleration, _ = pulled(position, mass, charge, 5.0, 0.0, external)
    got = [a.copy() for a in (position, velocity, acceleration)]
    want = [a.copy() for a in (position, velocity, acceleration)]
    record, heat = np.empty((20, len(RECORD))), np.empty(20)
    flown, after = smooth_intervals(*got, mass, radius, charge, 5.0, 0.0, *external, BOX, 5.0,
                                    5.0, np.nan, NONE, 0.0, 0, 0.05, 20, 1, np.nan, False,
                                    TOLERANCE, MOST, FLOOR, 1.5, record, heat)  # fmt: skip
    twin = reference.smooth_intervals(*want, mass, radius, charge, 5.0, 0.0, *external, BOX,
                                      np.array([5.0, 5.0]), np.nan, NONE, 0.0, 0, 0.05, 20, 1,
                                      TOLERANCE, MOST, FLOOR, 1.5, CONTACT_MARGIN)  # fmt: skip
    assert (flown, after) == twin[:2] and flown >= 10
    np.testing.assert_allclose(record[:flown], twin[2][:, :-1], rtol=1e-11, atol=1e-12)
    # The drag's energy ``m v^2 (f^2 - 1) / 2`` magnifies an ulp of ``f = exp(-gamma h / m)``
    # (NumPy's and numba's differ) by ``m / (2 gamma h)``, about 200 here: as the motion.
    np.testing.assert_allclose(heat[:flown], twin[2][:, -1], rtol=1e-10)
    assert (heat[flown - 1] < 1.5) == (kind == "falling")
    for ours, theirs in zip(got, want, strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=1e-10, atol=1e-12)


def test_an_interval_that_meets_a_wall_is_left_as_it_began():
    """The outer charge flung at a wall: the intervals before the one that meets it are taken,
    that one is put back bit for bit (the state the intervals before left), and the substep
    count is that of the last interval taken."""
    position, velocity, mass, radius, charge = three_bodies()
    velocity[2] = [0.0, -20.0]  # 3 m from the wall: in the fourth interval of 0.05 s
    acceleration = accelerations(position, mass, charge, 5.0, 0.0)
    state = [a.copy() for a in (position, velocity, acceleration)]
    record = np.empty((10, len(RECORD)))
    flown, after = smooth_intervals(*state, mass, radius, charge, 5.0, 0.0, *FREE, BOX, 5.0,
                                    5.0, np.nan, NONE, 0.0, 0, 0.05, 10, 1, np.nan, True,
                                    TOLERANCE, MOST, FLOOR, 0.0, record, np.empty(10))  # fmt: skip
    assert 1 <= flown <= 3
    before = [a.copy() for a in (position, velocity, acceleration)]
    _, want = smooth_intervals(*before, mass, radius, charge, 5.0, 0.0, *FREE, BOX, 5.0, 5.0,
                               np.nan, NONE, 0.0, 0, 0.05, flown, 1, np.nan, True, TOLERANCE,
                               MOST, FLOOR, 0.0, record, np.empty(10))  # fmt: skip
    assert after == want
    for ours, theirs in zip(state, before, strict=True):
        np.testing.assert_array_equal(ours, theirs)


def test_intervals_that_need_too_many_substeps_are_left_to_the_integrator():
    """Charges 1 mm apart at rest: the first interval needs more substeps than the most, and
    nothing is taken (the integrator then stops the run with its message)."""
    position = np.array([[0.0, 0.0], [0.001, 0.0]])
    state = [position, np.zeros((2, 2)), np.zeros((2, 2))]
    flown, after = smooth_intervals(*state, np.ones(2), np.zeros(2), np.array([1.0, -1.0]), 5.0,
                                    0.0, *FREE, BOX, 5.0, 5.0, np.nan, NONE, 0.0, 0, 1.0, 4, 2,
                                    np.nan, True, 1e-4, 16, FLOOR, 0.0,
                                    np.empty((4, len(RECORD))), np.empty(4))  # fmt: skip
    assert (flown, after) == (0, 2)
    np.testing.assert_array_equal(state[0], [[0.0, 0.0], [0.001, 0.0]])


@pytest.mark.parametrize("ratio", [0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 1000.0, 1024.0, 1025.0, 2e9])
def test_needed_is_the_smallest_power_of_two_that_keeps_the_substep_within_the_tolerance(ratio):
    """``dt sqrt(rate2) / tolerance`` = ``ratio`` substeps' worth: the next power of two, exact
    powers kept, capped at the most."""
    rate2 = (ratio * 0.001 / 0.01) ** 2
    assert needed(rate2, 0.01, 0.001, MOST) == reference.needed(rate2, 0.01, 0.001, MOST)
    assert needed(rate2, 0.01, 0.001, MOST) == min(MOST, max(1, 2 ** math.ceil(math.log2(ratio))))
    assert needed(np.nan, 0.01, 0.001, MOST) == MOST


def near_disks(position, velocity, radius, half, h):
    """The disks whose straight paths over ``h`` s come within their contact distance of
    another's or of a wall of a box of half sides ``half`` (m): all pairs, in NumPy."""
    d = position[None, :, :] - position[:, None, :]
    w = velocity[None, :, :] - velocity[:, None, :]
    w2 = np.einsum("ijk,ijk->ij", w, w)
    with np.errstate(divide="ignore", invalid="ignore"):
        along = np.clip(np.nan_to_num(-np.einsum("ijk,ijk->ij", d, w) / w2), 0.0, h)
    closest = d + w * along[:, :, None]
    sigma = radius[:, None] + radius[None, :]
    meets = np.einsum("ijk,ijk->ij", closest, closest) <= sigma**2
    np.fill_diagonal(meets, False)
    reach = np.abs(position) + np.abs(velocity) * h + radius[:, None]
    return meets.any(axis=1) | (reach >= half).any(axis=1)


def test_a_contact_drift_searching_pairs_for_the_near_disks_alone_runs_the_same_bits():
    """A substep's drift by the exact engine whose queue searches pairs only for the disks that
    may meet a contact (`collidium.kernels.events.rebuild_near`) runs the same events, to the
    bit, as one that searches for every disk: in the charged gas, over a drift in which a
    tenth of the disks may meet contacts."""
    import collidium as cd

    sim = cd.load("charged-gas")
    sim.run(steps=20)
    p, flight = sim.particles, sim._integrator._flight
    h = 0.02
    half = 0.5 * np.asarray(sim.container.size)
    near = near_disks(p.position, p.velocity, p.radius, half, h)
    assert 10 < near.sum() < p.n / 2
    runs = []
    for searched in (np.ones(p.n, dtype=bool), near):
        contacts = [
            tuple(np.copy(a) for a in item) if isinstance(item, tuple) else np.copy(item)
            for item in flight._contacts(p, sim.tally)
        ]
        position, kicked, flown = p.position.copy(), p.velocity.copy(), np.empty_like(p.position)
        done = substeps._contact_drift(position, kicked, flight.radius, flight.mass,
                                       sim._field.acceleration, 0.0, h, tuple(contacts),
                                       searched, flown)  # fmt: skip
        log, logged = contacts[4], contacts[5]
        runs.append((done, flown, kicked, log[: logged[0]], contacts[7]))
    full, pruned = runs
    assert full[0] > 20 and full[3].shape[0] > 5  # events, contacts logged
    assert full[0] == pruned[0]
    for a, b in zip(full[1:], pruned[1:], strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("vessel", ["box", "circle"])
def test_a_flight_that_stays_in_the_disks_rooms_meets_no_contact(rng, vessel):
    """Each disk's room (`substeps._rooms`, kept from the last contact test that found none)
    lets the substeps skip the test while every flight stays in it (`substeps._in_rooms`):
    every flight it lets through, the contact test, and the twin's all-pairs test, find free
    of contacts; many are let through, and none where a disk leaves its room."""
    shape, half, rim, table = WALLS[vessel]
    walls = (shape, half[0], half[1], rim, table)
    still = np.zeros((6, 2))
    none = (rng.uniform(-1.0, 1.0, (6, 2)), np.full(6, -1.0))  # before any test, or no room
    assert not substeps._in_rooms(none[0], still, 0.0, *none)
    through = 0
    for _ in range(40):
        position, _, _, _, _, _, _ = scene(rng, 6, spread=rng.uniform(1.0, 3.5))
        radius = rng.uniform(0.0, 0.4, 6)
        centres, rooms = np.empty((6, 2)), np.empty(6)
        substeps._rooms(position, radius, walls, centres, rooms)
        for _ in range(50):
            moved = position + rng.normal(0.0, 0.3, (6, 1)) * rng.normal(0.0, 0.3, (6, 2))
            velocity = rng.normal(0.0, 1.0, (6, 2))
            lag = rng.uniform(0.0, 0.3)
            if not substeps._in_rooms(moved, velocity, lag, centres, rooms):
                continue
            through += 1
            ends = moved + velocity * lag * (1.0 + CONTACT_MARGIN)
            assert np.all(np.hypot(*(moved - centres).T) < rooms)
            assert np.all(np.hypot(*(ends - centres).T) < rooms)
            order, low, high, near = np.arange(6), np.empty(6), np.empty(6), np.empty(6, bool)
            assert not substeps._contacts_ahead(moved, velocity, radius, lag, walls, order, low,
                                                high, near)  # fmt: skip
            if shape == BOX:
                wall = reference._next_wall(moved, velocity, radius, half)[0]
            else:
                wall = reference._next_rim(moved, velocity, radius, rim, np.zeros(2))[0]
            assert wall > lag
            assert not near_disks(moved, velocity, radius, np.array([np.inf, np.inf]), lag).any()
    assert through > 200
