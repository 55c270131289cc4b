"""Remaining kernels against their NumPy twins: wall drifts, placement, audit."""

from __future__ import annotations

import numpy as np
import pytest

from collidium.kernels import reference
from collidium.kernels.audit import first_invalid
from collidium.kernels.placement import place_disks
from collidium.kernels.walls import drift_periodic, drift_reflecting


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


@pytest.mark.parametrize("periodic", [False, True])
def test_audit_equals_twin(rng, periodic):
    position = rng.uniform(-4.9, 4.9, (200, 2))
    velocity = rng.normal(0, 1, (200, 2))
    radius = np.full(200, 0.05)
    half = np.array([5.0, 5.0])
    assert first_invalid(position, velocity, radius, 5.0, 5.0, periodic, 1e-9) == (-1, 0)
    cases = [(57, "position", [4.97, 0.0]), (33, "velocity", [np.nan, 0.0]),
             (12, "position", [0.0, -5.2])]  # fmt: skip
    for index, field, value in cases:
        p, v = position.copy(), velocity.copy()
        (p if field == "position" else v)[index] = value
        want = reference.first_invalid(p, v, radius, half, periodic, 1e-9)
        assert first_invalid(p, v, radius, 5.0, 5.0, periodic, 1e-9) == want
        assert want[0] == index or (periodic and value == [4.97, 0.0])
