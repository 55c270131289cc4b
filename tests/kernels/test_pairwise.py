"""Coulomb direct sum: gradient of the potential, Newton's third law, NumPy twin, threads."""

from __future__ import annotations

import itertools
import math

import numba
import numpy as np
import pytest

from collidium.kernels import pairwise, reference
from collidium.kernels.pairwise import (
    PARALLEL_DIRECT_FROM,
    inverse_distance_direct,
    inverse_distance_stiffness,
)


def _coulomb(position, charge, k=5.0, eps2=0.0, size=None):
    n = len(position)
    force = np.empty((n, 2))
    energy = np.empty(n)
    virial = np.empty(n)
    periodic = size is not None
    w, h = size if periodic else (0.0, 0.0)
    inverse_distance_direct(position, charge, k, eps2, w, h, periodic, force, energy, virial)
    return force, energy, virial


@pytest.fixture
def charges(rng):
    n = 40
    position = rng.uniform(-8, 8, (n, 2))
    charge = rng.choice([-1.0, 1.0, 0.5, 0.0], n)
    return position, charge


@pytest.mark.parametrize("eps2", [0.0, 0.05**2])
def test_forces_are_minus_the_gradient_of_the_potential(charges, eps2):
    position, charge = charges
    force, *_ = _coulomb(position, charge, eps2=eps2)
    h = 1e-6
    for i in (0, 7, 21):
        for d in range(2):
            plus, minus = position.copy(), position.copy()
            plus[i, d] += h
            minus[i, d] -= h
            u_plus = _coulomb(plus, charge, eps2=eps2)[1].sum()
            u_minus = _coulomb(minus, charge, eps2=eps2)[1].sum()
            gradient = (u_plus - u_minus) / (2 * h)
            # Central difference: O(h^2) truncation plus round-off of U / h.
            tolerance = 1e-6 * max(1.0, abs(force[i, d]))
            assert abs(force[i, d] + gradient) < tolerance


def test_forces_sum_to_zero(charges):
    position, charge = charges
    force, *_ = _coulomb(position, charge)
    scale = np.abs(force).sum()
    np.testing.assert_allclose(force.sum(axis=0), 0.0, atol=1e-14 * scale)


def test_potential_of_two_charges_is_k_q1_q2_over_r():
    force, energy, virial = _coulomb(np.array([[-2.0, 0.0], [2.0, 0.0]]), np.array([1.0, -1.0]))
    assert energy.sum() == pytest.approx(-5.0 / 4.0, rel=1e-15)
    assert force[0, 0] == pytest.approx(5.0 / 16.0, rel=1e-15)  # attracted to the right
    # r_12 . F_12 = (-4) * (5/16) for the attracting pair: equal to U for an inverse-r potential.
    assert virial.sum() == pytest.approx(-5.0 / 4.0, rel=1e-15)


# A quarter neutral: about 30, 128 (two or three blocks: an odd count has a middle row), 384
# (in parallel) and 1125 charges (blocks of more than 64).
@pytest.mark.parametrize("n", [40, 170, 2 * PARALLEL_DIRECT_FROM, 1500])
@pytest.mark.parametrize("periodic", [False, True])
def test_kernel_equals_numpy_twin(rng, n, periodic):
    position = rng.uniform(-8, 8, (n, 2))
    charge = rng.choice([-1.0, 1.0, 0.5, 0.0], n)
    size = np.array([16.0, 16.0]) if periodic else None
    got_force, got_energy, got_virial = _coulomb(position, charge, eps2=0.01, size=size)
    want = reference.inverse_distance_direct(position, charge, 5.0, 0.01, size)
    np.testing.assert_allclose(got_force, want[0], rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(got_energy, want[1], rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(got_virial, want[2], rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize("periodic", [False, True])
def test_results_do_not_depend_on_the_number_of_threads(rng, periodic):
    """Each task sums into its own buffer and the buffers are added up in task order: bit for
    bit the same with 1 or 2 threads."""
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs two threads")
    n = 1500
    position = rng.uniform(-50, 50, (n, 2))
    charge = rng.choice([-1.0, 1.0, 2.0, 0.0], n)
    size = np.array([100.0, 100.0]) if periodic else None
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        single = _coulomb(position, charge, eps2=0.01, size=size)
        numba.set_num_threads(2)
        double = _coulomb(position, charge, eps2=0.01, size=size)
    finally:
        numba.set_num_threads(before)
    for a, b in zip(single, double, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("periodic", [False, True])
def test_rows_in_serial_and_in_parallel_are_bitwise_the_same(rng, periodic):
    """Small scenes sum on one thread (`PARALLEL_DIRECT_FROM`): that changes no bit."""
    n = 300
    position = rng.uniform(-50, 50, (n, 2))
    velocity = rng.normal(0.0, 3.0, (n, 2))
    charge = rng.choice([-1.0, 1.0, 2.0, 0.0], n)
    mass = rng.uniform(0.1, 2.0, n)
    outputs = []
    for rows in (pairwise.direct_serial, pairwise.direct_parallel):
        force, energy, virial = np.full((n, 2), np.nan), np.full(n, np.nan), np.full(n, np.nan)
        rows(position, charge, 5.0, 0.01, 100.0, 100.0, periodic, force, energy, virial, True)
        outputs.append((force, energy, virial))
    for a, b in zip(*outputs, strict=True):
        assert np.isfinite(a).all()
        np.testing.assert_array_equal(a, b)
    stiffness = [
        rows(position, velocity, charge, mass, 5.0, 0.01, 100.0, 100.0, periodic)
        for rows in (pairwise.stiffness_serial, pairwise.stiffness_parallel)
    ]
    assert stiffness[0] > 0.0 and stiffness[0] == stiffness[1]


# One task (up to 128 charges), a task per pair of block rows on one thread, and in parallel.
@pytest.mark.parametrize("n", [40, 200, 2 * PARALLEL_DIRECT_FROM])
@pytest.mark.parametrize("periodic", [False, True])
def test_forces_alone_are_bitwise_those_summed_with_the_energies(rng, n, periodic):
    """A kick sums the forces alone: the same bits as with the energies (so that reading the
    energies never changes a trajectory), and the energy arrays left as they were."""
    position = rng.uniform(-8, 8, (n, 2))
    charge = rng.choice([-1.0, 1.0, 0.5, 0.0], n)
    size = np.array([16.0, 16.0]) if periodic else None
    with_energies = _coulomb(position, charge, eps2=0.01, size=size)[0]
    alone = np.full((n, 2), np.nan)
    w, h = size if periodic else (0.0, 0.0)
    inverse_distance_direct(position, charge, 5.0, 0.01, w, h, periodic, alone)
    np.testing.assert_array_equal(alone, with_energies)
    for rows in (pairwise.direct_serial, pairwise.direct_parallel):
        force, energy, virial = np.full((n, 2), np.nan), np.full(n, 7.0), np.full(n, 7.0)
        rows(position, charge, 5.0, 0.01, w, h, periodic, force, energy, virial, False)
        np.testing.assert_array_equal(force, with_energies)
        assert np.all(energy == 7.0) and np.all(virial == 7.0)


@pytest.mark.parametrize("n", [5, 40, 200])  # a plain loop, one task, tasks on one thread
def test_pair_sums_without_the_energies_sum_the_same_forces(rng, n):
    """`pair_sums` told to leave the energies out (the compiled substeps but an interval's
    last) gives the forces of the sums with them, to round-off (LLVM may split the two loops'
    reductions differently), and zeros for the energies and virials."""
    x, y = rng.uniform(-8, 8, n), rng.uniform(-8, 8, n)
    q = rng.choice([-1.0, 1.0, 0.5], n)
    buffer = np.empty(4 * n * pairwise.MOST_BLOCKS)
    full, alone = np.full((4, n), np.nan), np.full((4, n), np.nan)
    pairwise.pair_sums(x, y, q, 5.0, 0.01, 0.0, 0.0, False, True, full, buffer)
    pairwise.pair_sums(x, y, q, 5.0, 0.01, 0.0, 0.0, False, False, alone, buffer)
    scale = np.abs(full[:2]).max()
    np.testing.assert_allclose(alone[:2], full[:2], rtol=1e-12, atol=1e-13 * scale)
    assert np.all(full[2:] != 0.0) and np.all(alone[2:] == 0.0)


def test_neutral_particles_feel_and_exert_nothing(rng):
    position = rng.uniform(-5, 5, (30, 2))
    charge = rng.choice([-1.0, 1.0], 30)
    charge[::3] = 0.0
    position[3] = position[4]  # a neutral particle on top of a charged one: still no force
    force, energy, virial = _coulomb(position, charge)
    assert np.all(force[::3] == 0) and np.all(energy[::3] == 0) and np.all(virial[::3] == 0)
    charged = charge != 0
    want = _coulomb(position[charged], charge[charged])
    np.testing.assert_array_equal(force[charged], want[0])
    np.testing.assert_array_equal(energy[charged], want[1])


@pytest.mark.parametrize("n", [2, 40, 300])  # 300 charges: rows in parallel
@pytest.mark.parametrize("periodic", [False, True])
def test_stiffness_equals_numpy_twin(rng, n, periodic):
    position = rng.uniform(-8, 8, (n, 2))
    velocity = rng.normal(0.0, 3.0, (n, 2))
    charge = rng.choice([-1.0, 2.0, 0.0], n)
    charge[:2] = 1.0
    mass = rng.uniform(0.1, 2.0, n)
    size = np.array([16.0, 16.0]) if periodic else None
    got = inverse_distance_stiffness(
        position, velocity, charge, mass, 5.0, 0.01, 16.0, 16.0, periodic
    )
    want = reference.inverse_distance_stiffness(position, velocity, charge, mass, 5.0, 0.01, size)
    assert got == pytest.approx(want, rel=1e-12)


def full_rows(x, y, vx, vy, q, inverse_mass, coupling, softening2):
    """Every row of the stiffness in full (`pairwise.stiffness_row`), the largest."""
    largest = 0.0
    for c in range(x.size):
        row = pairwise.stiffness_row(c, x, y, vx, vy, q, inverse_mass, coupling, softening2, 0.0,
                                     0.0, False, x.size)  # fmt: skip
        largest = pairwise.larger(largest, row)
    return largest


@pytest.mark.parametrize("softening2", [0.0, 0.01, 4.0])
def test_pruned_stiffness_is_every_row_bit_for_bit(rng, softening2):
    """Gases of 32 to 300 particles, charges and masses of several sizes, one pair touching:
    leaving out the pairs too far apart along x to matter gives the same bits, from any order."""
    for n in (32, 57, 200, 300):
        x, y = rng.uniform(-10.0, 10.0, (2, n))
        x[1], y[1] = x[0] + 0.5, y[0]  # one pair close
        vx, vy = rng.normal(0.0, 7.0, (2, n))
        q = rng.choice([-1.0, 1.0, 2.5], n)
        inverse_mass = 1.0 / rng.uniform(0.5, 3.0, n)
        want = full_rows(x, y, vx, vy, q, inverse_mass, 5.0, softening2)
        for order in (np.arange(n), rng.permutation(n)):
            got = pairwise.pruned_stiffness(x, y, vx, vy, q, inverse_mass, 5.0, softening2, order,
                                            np.empty((6, n)))  # fmt: skip
            assert got == want and np.all(np.diff(x[order]) >= 0.0)  # left sorted


def test_pruned_stiffness_finds_the_largest_pair_past_its_neighbours_along_x(rng):
    """The hardest pair is not a pair of neighbours along x (disks lie between them in x, far
    away in y), so the first largest is small and the bound shrinks as the rows find larger
    ones: still the same bits as every row, from any order."""
    n = 100
    x, y = np.linspace(-10.0, 10.0, n), np.where(np.arange(n) % 2 == 0, 6.0, -6.0)
    vx, vy = np.zeros(n), np.zeros(n)
    x[:2], y[:2], vx[:2] = [0.0, 0.4], [0.0, 0.3], [100.0, -100.0]  # 0.5 m apart, closing fast
    x[2:6], y[2:6] = [0.1, 0.2, 0.3, 0.35], [8.0, -8.0, 9.0, -9.0]
    q, inverse_mass = np.ones(n), np.ones(n)
    want = full_rows(x, y, vx, vy, q, inverse_mass, 5.0, 0.0)
    pairs = [list(pair) for pair in itertools.pairwise(np.argsort(x))]
    neighbours = max(full_rows(x[pair], y[pair], vx[pair], vy[pair], q[pair], inverse_mass[pair],
                               5.0, 0.0) for pair in pairs)  # fmt: skip
    assert neighbours < want / 100  # the first largest is far from the pair's
    for order in (np.arange(n), rng.permutation(n)):
        got = pairwise.pruned_stiffness(x, y, vx, vy, q, inverse_mass, 5.0, 0.0, order,
                                        np.empty((6, n)))  # fmt: skip
        assert got == want


@pytest.mark.parametrize("bad", [math.inf, math.nan])
def test_pruned_stiffness_keeps_a_value_that_is_not_finite(rng, bad):
    """A position or velocity that is not finite: every row in full, the same value (NaN for a
    NaN; an infinitely distant particle pulls with nothing)."""
    n = 64
    for where in (0, 3):
        values = rng.uniform(-10.0, 10.0, (4, n))
        values[where, 17] = bad
        want = full_rows(*values, np.ones(n), np.ones(n), 5.0, 0.0)
        got = pairwise.pruned_stiffness(*values, np.ones(n), np.ones(n), 5.0, 0.0, np.arange(n),
                                        np.empty((6, n)))  # fmt: skip
        assert got == want or (math.isnan(got) and math.isnan(want))
        assert math.isnan(got) == math.isnan(bad)


def test_stiffness_of_a_pair_is_its_energy_times_its_squared_rate():
    """Two charges 2 m apart closing at 3 m/s: |U| = 5 * 2 / 2, rate^2 = (9 + |U| * 2) / 4."""
    position = np.array([[-1.0, 0.0], [1.0, 0.0]])
    velocity = np.array([[1.5, 0.0], [-1.5, 0.0]])
    charge, mass = np.array([1.0, -2.0]), np.array([1.0, 1.0])
    got = inverse_distance_stiffness(position, velocity, charge, mass, 5.0, 0.0, 0.0, 0.0, False)
    assert got == pytest.approx((5.0 * (9.0 + 10.0) / 4.0) ** 2, rel=1e-14)
    charge[1] = 0.0  # a neutral particle counts for nothing
    assert (
        inverse_distance_stiffness(position, velocity, charge, mass, 5.0, 0.0, 0.0, 0.0, False)
        == 0.0
    )


@pytest.mark.parametrize("bad", [math.inf, math.nan])
@pytest.mark.parametrize("rows", [pairwise.stiffness_serial, pairwise.stiffness_parallel])
def test_a_non_finite_pair_stiffness_is_the_largest(rng, bad, rows):
    """The rows take their maximum over bit patterns: an infinite or NaN velocity of the last
    particle, met in every row's last pair, still gives an infinite or NaN stiffness."""
    n = 40
    position = rng.uniform(-8, 8, (n, 2))
    velocity = rng.normal(0.0, 3.0, (n, 2))
    velocity[-1, 0] = bad
    charge, mass = rng.choice([-1.0, 2.0], n), np.ones(n)
    got = rows(position, velocity, charge, mass, 5.0, 0.01, 0.0, 0.0, False)
    assert got == bad or (math.isnan(bad) and math.isnan(got))
