"""Barnes-Hut tree for the Coulomb force: accuracy against the direct sum, NumPy twin, thread
independence and degenerate inputs."""

from __future__ import annotations

import itertools

import numba
import numpy as np
import pytest

from collidium.kernels import reference
from collidium.kernels.pairwise import inverse_distance_direct
from collidium.kernels.tree import (
    LEAF_SIZE,
    THETA,
    acceleration_stiffness,
    inverse_distance_tree,
    tree_buffers,
)

K = 5.0


def _tree(position, charge, eps2=0.0, theta=THETA, leaf_size=LEAF_SIZE, buffers=None):
    n = len(position)
    force, energy, virial = np.full((n, 2), np.nan), np.full(n, np.nan), np.full(n, np.nan)
    if buffers is None:
        buffers = tree_buffers(n, leaf_size)
    inverse_distance_tree(
        position, charge, K, eps2, force, energy, virial, buffers, theta, leaf_size
    )
    return force, energy, virial


def _direct(position, charge, eps2=0.0):
    n = len(position)
    force, energy, virial = np.empty((n, 2)), np.empty(n), np.empty(n)
    inverse_distance_direct(position, charge, K, eps2, 0.0, 0.0, False, force, energy, virial)
    return force, energy, virial


def _rms_relative_force_error(force, exact):
    """sqrt(mean_i |F_i - F_exact_i|^2 / |F_exact_i|^2)."""
    return np.sqrt(np.mean(np.sum((force - exact) ** 2, axis=1) / np.sum(exact**2, axis=1)))


def _neutral_gas(rng, n):
    """Charges +1/-1 alternating, uniform in a square of 40000 m^2 (about 200 m^2 per particle
    for n = 200, the seed's density scale)."""
    position = rng.uniform(-100.0, 100.0, (n, 2))
    charge = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    return position, charge


@pytest.fixture(scope="module")
def gas():
    return _neutral_gas(np.random.default_rng(20241203), 3000)


@pytest.mark.parametrize("eps2", [0.0, 0.05**2])
def test_default_theta_keeps_rms_force_error_below_1e_3(gas, eps2):
    position, charge = gas
    force, energy, virial = _tree(position, charge, eps2)
    exact = _direct(position, charge, eps2)
    assert _rms_relative_force_error(force, exact[0]) < 1e-3
    # Per-particle energies and virials: most of each comes from the exactly summed near field.
    for got, want in ((energy, exact[1]), (virial, exact[2])):
        assert np.linalg.norm(got - want) < 1e-4 * np.linalg.norm(want)
        # Totals of a neutral gas cancel: compare against the sum of magnitudes.
        assert abs(got.sum() - want.sum()) < 1e-5 * np.abs(want).sum()


def test_force_error_falls_as_theta_to_the_fifth(gas):
    """The order-4 expansion's truncation error scales as theta^5: the error decreases with the
    opening angle and stays below theta^5 / 10 (measured: at most theta^5 / 38)."""
    position, charge = gas
    exact = _direct(position, charge, 0.05**2)[0]
    buffers = tree_buffers(len(position))
    thetas = [0.8, 0.45, 0.3, 0.2, 0.1]
    errors = [
        _rms_relative_force_error(_tree(position, charge, 0.05**2, t, buffers=buffers)[0], exact)
        for t in thetas
    ]
    assert all(later < earlier for earlier, later in itertools.pairwise(errors))
    for theta, error in zip(thetas, errors, strict=True):
        assert error < 0.1 * theta**5


@pytest.mark.parametrize("eps2", [0.0, 0.05**2])
def test_theta_zero_opens_every_node_and_equals_direct_sum(eps2):
    position, charge = _neutral_gas(np.random.default_rng(7), 700)
    got = _tree(position, charge, eps2, theta=0.0, leaf_size=16)
    want = _direct(position, charge, eps2)
    for g, w in zip(got, want, strict=True):
        np.testing.assert_allclose(g, w, rtol=0, atol=1e-12 * np.abs(w).max())


@pytest.mark.parametrize(("eps2", "theta", "leaf_size"), [(0.0, 0.5, 8), (0.01, 0.7, 4)])
def test_kernel_equals_numpy_twin(rng, eps2, theta, leaf_size):
    # The twin writes the expansion out from each node's particles: this checks the kernel's
    # moments, their translation and its hand-expanded polynomials to round-off.
    n = 250
    position = rng.uniform(-8, 8, (n, 2))
    charge = rng.choice([-1.0, 1.0, 0.5, 0.0], n)
    got = _tree(position, charge, eps2, theta, leaf_size)
    want = reference.inverse_distance_tree(position, charge, K, eps2, theta, leaf_size)
    for g, w in zip(got, want, strict=True):
        np.testing.assert_allclose(g, w, rtol=0, atol=1e-13 * np.abs(w).max())
    # And the tree is really approximating here (not a disguised direct sum).
    assert not np.allclose(got[0], _direct(position, charge, eps2)[0], rtol=1e-9, atol=0)


def test_results_do_not_depend_on_the_number_of_threads(gas):
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs two threads")
    position, charge = gas
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        single = _tree(position, charge, 0.05**2)
        numba.set_num_threads(2)
        double = _tree(position, charge, 0.05**2)
    finally:
        numba.set_num_threads(before)
    for a, b in zip(single, double, strict=True):
        np.testing.assert_array_equal(a, b)


def test_no_particles_and_one_particle():
    empty = _tree(np.empty((0, 2)), np.empty(0))
    assert [a.shape for a in empty] == [(0, 2), (0,), (0,)]
    force, energy, virial = _tree(np.array([[1.0, 2.0]]), np.array([3.0]), 0.01)
    np.testing.assert_array_equal(force, 0.0)
    np.testing.assert_array_equal(energy, 0.0)
    np.testing.assert_array_equal(virial, 0.0)


def test_all_charges_zero(rng):
    position = rng.uniform(-5, 5, (500, 2))
    for result in _tree(position, np.zeros(500)):
        np.testing.assert_array_equal(result, 0.0)


def test_coincident_particles_are_softened(rng):
    # 100 particles on one point (deeper than the finest cell: one overfull leaf) among others.
    position = np.vstack([np.full((100, 2), 1.5), rng.uniform(-10, 10, (600, 2))])
    charge = rng.choice([-1.0, 1.0], 700)
    eps2 = 0.1**2
    got = _tree(position, charge, eps2)
    want = _direct(position, charge, eps2)
    assert all(np.isfinite(a).all() for a in got)
    assert _rms_relative_force_error(got[0], want[0]) < 1e-3
    assert abs(got[1].sum() - want[1].sum()) < 1e-5 * np.abs(want[1]).sum()


def test_all_particles_on_one_point(rng):
    position = np.zeros((100, 2))
    charge = rng.choice([-1.0, 1.0], 100)
    got = _tree(position, charge, 0.01)
    want = _direct(position, charge, 0.01)
    for g, w in zip(got, want, strict=True):
        np.testing.assert_allclose(g, w, rtol=0, atol=1e-12 * max(np.abs(w).max(), 1.0))


def test_neutral_particle_on_a_charged_one_gets_no_nan_without_softening(rng):
    # The direct sum skips neutral particles; so must the tree, or 0 * inf would appear.
    position = rng.uniform(-10, 10, (200, 2))
    position[1] = position[0]
    charge = rng.choice([-1.0, 1.0], 200)
    charge[1] = 0.0
    got = _tree(position, charge)
    want = _direct(position, charge)
    assert all(np.isfinite(a).all() for a in got)
    np.testing.assert_array_equal(got[0][1], 0.0)
    assert _rms_relative_force_error(np.delete(got[0], 1, 0), np.delete(want[0], 1, 0)) < 1e-3


@pytest.mark.parametrize("axis", [0, 1])
def test_particles_on_a_line(rng, axis):
    # The bounding box has zero width in one direction; cell centres lie off the line.
    n = 1000
    position = np.zeros((n, 2))
    position[:, axis] = rng.uniform(-50, 50, n)
    charge = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    got = _tree(position, charge, 0.05**2)
    want = _direct(position, charge, 0.05**2)
    assert all(np.isfinite(a).all() for a in got)
    # The exact force is along the line; the expansions about off-line centres leave a
    # perpendicular part of the size of their truncation error.
    assert np.all(np.abs(got[0][:, 1 - axis]) < 1e-3 * np.abs(got[0][:, axis]))
    assert _rms_relative_force_error(got[0], want[0]) < 1e-3


def test_buffers_grow_for_a_tree_with_many_small_leaves(rng):
    # Buffers sized for huge leaves, then a tree with tiny ones: node arrays must grow in place.
    n = 2000
    position = np.vstack([rng.normal(0, 0.01, (n // 2, 2)), rng.uniform(-50, 50, (n // 2, 2))])
    charge = rng.choice([-1.0, 1.0], n)
    buffers = tree_buffers(n, leaf_size=10**6)
    capacity = buffers["leaves"].shape[0]
    got = _tree(position, charge, 1e-4, leaf_size=2, buffers=buffers)
    assert buffers["leaves"].shape[0] > capacity
    assert _rms_relative_force_error(got[0], _direct(position, charge, 1e-4)[0]) < 1e-3
    # A different N reallocates the per-particle arrays.
    got = _tree(position[:500], charge[:500], 1e-4, buffers=buffers)
    assert buffers["order"].shape == (500,)
    assert _rms_relative_force_error(got[0], _direct(position[:500], charge[:500], 1e-4)[0]) < 1e-3


@pytest.mark.parametrize("radius, softening", [(0.1, 0.05), (0.01, 0.05), (0.0, 0.0)])
def test_acceleration_stiffness_equals_numpy_twin(rng, radius, softening):
    # Disks wider than the softening, softened points, and bare points (the mean spacing).
    n = 500
    velocity = rng.normal(0, 2, (n, 2))
    acceleration = rng.normal(0, 50, (n, 2))
    mass = rng.uniform(0.5, 2, n)
    radii = np.full(n, radius)
    args = (velocity, acceleration, mass, radii, softening, 0.3)
    got = acceleration_stiffness(*args)
    assert got > 0.0
    assert got == pytest.approx(reference.acceleration_stiffness(*args), rel=1e-14)
    # The largest term: raising one particle's pull raises the result to that particle's.
    acceleration[7] = 1e4
    assert acceleration_stiffness(*args) == pytest.approx(
        reference.acceleration_stiffness(*args), rel=1e-14
    )
    assert acceleration_stiffness(*args) > got


def test_acceleration_stiffness_keeps_a_nan():
    # A non-finite acceleration must reach the substep rate, which then refuses the step.
    acceleration = np.array([[1.0, 0.0], [np.nan, 0.0], [2.0, 0.0]])
    got = acceleration_stiffness(np.ones((3, 2)), acceleration, np.ones(3), np.ones(3), 0.0, 1.0)
    assert np.isnan(got)
