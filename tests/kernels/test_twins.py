"""Remaining kernels against their NumPy twins: wall drifts, placement, audit."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from collidium.kernels import reference
from collidium.kernels.audit import all_valid, first_invalid, first_past_face
from collidium.kernels.placement import place_disks
from collidium.kernels.vessels import BOX, CIRCLE
from collidium.kernels.vessels.box import DRIFT_CHUNK, drift_periodic, drift_reflecting, fold

#: No segments: a vessel without partitions.
NONE = np.empty((0, 9))


def test_reflecting_drift_equals_twin(rng):
    n = 500
    radius = rng.uniform(0.0, 0.5, n)
    position = rng.uniform(-4.4, 4.4, (n, 2))
    velocity = rng.normal(0.0, 30.0, (n, 2))  # many bounces per step
    mass = rng.uniform(0.5, 2.0, n)
    got_p, got_v, hits = position.copy(), velocity.copy(), np.zeros(4, np.int64)
    impulse = np.zeros(4)
    drift_reflecting(got_p, got_v, radius, mass, 5.0, 5.0, 0.7, hits, impulse)
    want_p, want_v = position.copy(), velocity.copy()
    want_hits, want_impulse = reference.drift_reflecting(
        want_p, want_v, radius, mass, np.array([5.0, 5.0]), 0.7
    )
    np.testing.assert_array_equal(hits, want_hits)
    np.testing.assert_allclose(impulse, want_impulse, rtol=1e-13)
    np.testing.assert_array_equal(got_v, want_v)
    # Folding once versus bouncing one span at a time: round-off of order (bounces) ulp.
    np.testing.assert_allclose(got_p, want_p, rtol=0, atol=1e-12)


def test_periodic_drift_equals_twin(rng):
    position = rng.uniform(-5, 5, (300, 2))
    velocity = rng.normal(0, 40, (300, 2))
    got_p, got_i = position.copy(), np.zeros((300, 2), np.int64)
    drift_periodic(got_p, velocity, got_i, 10.0, 10.0, 0.9)
    want_p, want_i = position.copy(), np.zeros((300, 2), np.int64)
    reference.drift_periodic(want_p, velocity, want_i, np.array([10.0, 10.0]), 0.9)
    np.testing.assert_array_equal(got_i, want_i)
    np.testing.assert_allclose(got_p, want_p, rtol=0, atol=1e-13)


def test_placement_equals_twin(rng):
    n, width, r = 400, 20.0, 0.3
    radius = np.full(n, r)
    candidates = rng.uniform(-width / 2 + r, width / 2 - r, (3000, 2))
    cell = 2 * r
    count = int(width // cell)
    head, next_ = np.full(count * count, -1, np.int64), np.full(n, -1, np.int64)
    got = np.zeros((n, 2))
    placed = place_disks(candidates, radius, 0, got, np.array([-10.0, -10.0]), width / count,
                         count, count, head, next_)  # fmt: skip
    want = np.zeros((n, 2))
    assert placed == reference.place_disks(candidates, radius, want, 0) == n
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("n", [200, 20_000])
@pytest.mark.parametrize(("shape", "periodic"), [(BOX, False), (BOX, True), (CIRCLE, False)])
def test_audit_equals_twin(rng, shape, periodic, n):
    """In one pass, or in parallel chunks (4 at N = 20,000): the first bad particle is found,
    wherever the bad ones lie, in a box of half side 5 m or a circle of radius 5 m; the flights'
    audit (`all_valid`, without branches in a box) says whether there is one."""
    position = rng.uniform(-3.5, 3.5, (n, 2))
    velocity = rng.normal(0, 1, (n, 2))
    radius = np.full(n, 0.05)
    limit = 5.0 * (1 + 1e-9)
    args = (shape, limit, limit, 0.0, periodic, NONE)
    assert first_invalid(position, velocity, radius, *args) == (-1, 0)
    assert all_valid(position, velocity, radius, *args)
    two_chunks = [(3 * n // 5, "position", [0.0, -5.2]), (n // 4 + 1, "velocity", [0.0, np.inf])]
    corner = [(7, "position", [3.6, 3.6])]  # inside the box, outside the circle
    cases = [[(57, "position", [4.97, 0.0])], [(n - 1, "velocity", [np.nan, 0.0])], two_chunks]
    for bad in [*cases, corner]:
        p, v = position.copy(), velocity.copy()
        for index, field, value in bad:
            (p if field == "position" else v)[index] = value
        want = reference.first_invalid(p, v, radius, *args)
        assert first_invalid(p, v, radius, *args) == want
        assert all_valid(p, v, radius, *args) == (want[0] < 0)
        found = min(index for index, *_ in bad)
        inside = (periodic and bad[0][0] == 57) or (shape == BOX and bad is corner)
        assert want[0] == (-1 if inside and len(bad) == 1 else found)


@pytest.mark.parametrize(("axis", "sign"), [(0, -1.0), (0, 1.0), (1, -1.0), (1, 1.0)])
def test_piston_audit_equals_twin(rng, axis, sign):
    """A piston's face at 2 m along either axis, facing either way: the first disk reaching past
    it by more than the allowance is found, as by the twin; none when all are behind it, and
    a centre that is not finite is left to `first_invalid`."""
    n = 300
    radius = np.full(n, 0.1)
    position = rng.uniform(-3.0, 3.0, (n, 2))
    position[:, axis] = sign * rng.uniform(-3.0, -2.1, n) + 2.0  # behind the face
    face = (axis, sign, 2.0, 1e-9)
    assert first_past_face(position, radius, *face) == reference.first_past_face(
        position, radius, *face
    ) == -1  # fmt: skip
    position[17, axis] = 2.0 - sign * 0.1 + sign * 2e-9  # past by twice the allowance
    position[9, axis] = 2.0 - sign * 0.1 + sign * 5e-10  # within it
    position[5] = np.nan
    assert first_past_face(position, radius, *face) == 17
    assert reference.first_past_face(position, radius, *face) == 17
    position[200, axis] = 2.0 + sign * 3.0
    assert first_past_face(position, radius, *face) == 17


def _fold_in_index_order(position, velocity, radius, mass, half, dt):
    """The sequential drift: `vessels.box.fold` particle by particle, wall tallies summed in
    order."""
    hits, impulse = np.zeros(4, np.int64), np.zeros(4)
    for i in range(len(position)):
        for d in range(2):
            moving_up = velocity[i, d] > 0
            x = position[i, d] + velocity[i, d] * dt
            x, v, bounces = fold(x, velocity[i, d], radius[i] - half, half - radius[i])
            position[i, d], velocity[i, d] = x, v
            first, other = 2 * d + int(moving_up), 2 * d + 1 - int(moving_up)
            hits[first] += (bounces + 1) // 2
            hits[other] += bounces // 2
            impulse[first] += 2 * mass[i] * abs(v) * ((bounces + 1) // 2)
            impulse[other] += 2 * mass[i] * abs(v) * (bounces // 2)
    return hits, impulse


def test_parallel_reflecting_drift_is_the_sequential_one_whatever_the_threads(rng):
    """Chunks drift in parallel up to their first wall hit; the rest is folded in index order,
    so positions, velocities and the wall tallies are bit for bit those of one sequential pass."""
    n = 5 * DRIFT_CHUNK + 17
    radius = rng.uniform(0.0, 0.3, n)
    position = rng.uniform(-4.5, 4.5, (n, 2))
    velocity = rng.normal(0.0, 1.0, (n, 2))
    velocity[rng.random(n) < 0.01] *= 40.0  # a few particles bounce, some several times
    mass = rng.uniform(0.5, 2.0, n)
    want_p, want_v = position.copy(), velocity.copy()
    want = _fold_in_index_order(want_p, want_v, radius, mass, 5.0, 0.7)
    before = numba.get_num_threads()
    try:
        for threads in range(1, min(2, numba.config.NUMBA_NUM_THREADS) + 1):
            numba.set_num_threads(threads)
            got_p, got_v = position.copy(), velocity.copy()
            hits, impulse = np.zeros(4, np.int64), np.zeros(4)
            drift_reflecting(got_p, got_v, radius, mass, 5.0, 5.0, 0.7, hits, impulse)
            np.testing.assert_array_equal(got_p, want_p)
            np.testing.assert_array_equal(got_v, want_v)
            np.testing.assert_array_equal(hits, want[0])
            np.testing.assert_array_equal(impulse, want[1])
    finally:
        numba.set_num_threads(before)
    assert want[0].sum() > 50
