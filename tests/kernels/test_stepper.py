"""The seed's step method and the overlap finder against their NumPy twins."""

from __future__ import annotations

import numpy as np

from collidium import Box, Particles
from collidium.collisions import StepCollisions, Tally
from collidium.kernels import reference
from collidium.kernels.cells import first_overlap, grid_shape


def _crowd(rng, n=300, width=10.0):
    position = rng.uniform(-width / 2 + 0.3, width / 2 - 0.3, (n, 2))
    radius = rng.uniform(0.05, 0.3, n)
    radius[::17] = 0.0  # points never overlap anything
    return position, radius


def test_overlapping_pairs_resolved_like_the_twin(rng):
    width = 10.0
    position, radius = _crowd(rng)
    n = len(position)
    velocity = rng.normal(0, 3, (n, 2))
    mass = rng.uniform(0.5, 2, n)
    particles = Particles(position.copy(), velocity.copy(), mass=mass, radius=radius)
    tally = Tally()
    StepCollisions().drift(particles, Box(width, width), 0.0, 0.0, tally)  # no flight: pairs only
    want_velocity = velocity.copy()
    want_done, want_virial = reference.step_collisions(position, want_velocity, mass, radius)
    assert tally.counts[0] == want_done > 20
    np.testing.assert_allclose(particles.velocity, want_velocity, rtol=1e-13, atol=1e-13)
    # Repulsive impulses along the line of centres: every term of the virial is positive.
    assert tally.impulse[0] > 0
    np.testing.assert_allclose(tally.impulse[0], want_virial, rtol=1e-12)


def test_first_overlap_equals_twin(rng):
    position, radius = _crowd(rng)
    ncx, ncy = grid_shape(10.0, 10.0, 2 * radius.max(), len(radius))
    assert first_overlap(position, radius, 10.0, 10.0, False, ncx, ncy) == (
        reference.first_overlap(position, radius)
    )
    apart = np.array([[-1.0, 0.0], [1.0, 0.0]])
    assert first_overlap(apart, np.array([0.5, 0.5]), 10.0, 10.0, False, 1, 1) == (-1, -1)


def test_periodic_overlap_across_the_edge_is_found():
    position = np.array([[-4.9, 0.0], [4.9, 0.0], [0.0, 0.0]])
    radius = np.full(3, 0.25)
    for ncx in (1, 2, 3, 20):
        assert first_overlap(position, radius, 10.0, 10.0, True, ncx, ncx) == (0, 1)
