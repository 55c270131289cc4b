"""Pair response (seed eq. 7): exact elastic cases and conservation laws, and the inelastic
response: momentum kept, the normal relative velocity scaled by e, elastic below the collapse
guard's speed."""

from __future__ import annotations

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from collidium.kernels import reference
from collidium.kernels.collision import pair_response

finite = st.floats(-50.0, 50.0, allow_nan=False)
masses = st.floats(1e-2, 1e2, allow_nan=False)
#: Restitution 1 and no collapse guard.
ELASTIC = (1.0, 0.0)


def test_head_on_equal_masses_swap_velocities():
    v = pair_response(1.0, 1.0, -0.5, 0.0, 5.0, 0.0, -5.0, 0.0, *ELASTIC)
    assert v == (-5.0, 0.0, 5.0, 0.0)


def test_unequal_masses_one_dimension_textbook():
    m1, m2, u1, u2 = 2.0, 0.5, 3.0, -1.0
    v1x, v1y, v2x, v2y = pair_response(m1, m2, -1.0, 0.0, u1, 0.0, u2, 0.0, *ELASTIC)
    expected_1 = ((m1 - m2) * u1 + 2 * m2 * u2) / (m1 + m2)
    expected_2 = ((m2 - m1) * u2 + 2 * m1 * u1) / (m1 + m2)
    np.testing.assert_allclose([v1x, v2x], [expected_1, expected_2], rtol=1e-15)
    assert v1y == v2y == 0.0


def test_glancing_contact_changes_only_the_normal_component():
    # Normal along x: the y components pass through untouched.
    v1x, v1y, v2x, v2y = pair_response(1.0, 1.0, -0.5, 0.0, 3.0, 2.0, 0.0, -1.0, *ELASTIC)
    assert (v1y, v2y) == (2.0, -1.0)
    assert (v1x, v2x) == (0.0, 3.0)


@settings(max_examples=300, deadline=None)
@given(masses, masses, finite, finite, finite, finite, finite, finite)
def test_collision_conserves_energy_and_momentum(m1, m2, nx, ny, v1x, v1y, v2x, v2y):
    if nx * nx + ny * ny < 1e-6:
        nx, ny = 1.0, 0.0
    w1x, w1y, w2x, w2y = pair_response(m1, m2, nx, ny, v1x, v1y, v2x, v2y, *ELASTIC)
    p_before = np.array([m1 * v1x + m2 * v2x, m1 * v1y + m2 * v2y])
    p_after = np.array([m1 * w1x + m2 * w2x, m1 * w1y + m2 * w2y])
    e_before = 0.5 * m1 * (v1x**2 + v1y**2) + 0.5 * m2 * (v2x**2 + v2y**2)
    e_after = 0.5 * m1 * (w1x**2 + w1y**2) + 0.5 * m2 * (w2x**2 + w2y**2)
    p_scale = max(abs(m1) * 50 + abs(m2) * 50, 1.0)
    assert np.abs(p_after - p_before).max() <= 1e-12 * p_scale
    assert abs(e_after - e_before) <= 1e-12 * max(e_before, 1.0)


@settings(max_examples=100, deadline=None)
@given(masses, masses, finite, finite, finite, finite, finite, finite)
def test_kernel_equals_numpy_twin(m1, m2, nx, ny, v1x, v1y, v2x, v2y):
    if nx * nx + ny * ny < 1e-6:
        nx, ny = 0.0, 1.0
    got = pair_response(m1, m2, nx, ny, v1x, v1y, v2x, v2y, *ELASTIC)
    w1, w2 = reference.pair_response(
        m1, m2, np.array([nx, ny]), np.zeros(2), np.array([v1x, v1y]), np.array([v2x, v2y])
    )
    np.testing.assert_allclose(got, [*w1, *w2], rtol=1e-12, atol=1e-12 * 50)


@settings(max_examples=300, deadline=None)
@given(masses, masses, finite, finite, finite, finite, finite, finite, st.floats(0.05, 1.0))
def test_an_inelastic_collision_keeps_momentum_and_takes_its_share_of_energy(
    m1, m2, nx, ny, v1x, v1y, v2x, v2y, e
):
    """For an approaching pair the normal relative velocity is reversed and scaled by e, so the
    kinetic energy drops by (1 - e^2) mu g_n^2 / 2; the twin works in the centre-of-mass
    frame."""
    if nx * nx + ny * ny < 1e-6:
        nx, ny = 1.0, 0.0
    assume((v1x - v2x) * nx + (v1y - v2y) * ny < 0.0)
    w1x, w1y, w2x, w2y = pair_response(m1, m2, nx, ny, v1x, v1y, v2x, v2y, e, 0.0)
    norm = np.hypot(nx, ny)
    before = ((v1x - v2x) * nx + (v1y - v2y) * ny) / norm
    after = ((w1x - w2x) * nx + (w1y - w2y) * ny) / norm
    assert abs(after + e * before) <= 1e-12 * 200
    p_scale = m1 * 100 + m2 * 100
    assert abs(m1 * (w1x - v1x) + m2 * (w2x - v2x)) <= 1e-12 * p_scale
    assert abs(m1 * (w1y - v1y) + m2 * (w2y - v2y)) <= 1e-12 * p_scale
    lost = 0.5 * m1 * (v1x**2 + v1y**2 - w1x**2 - w1y**2) + 0.5 * m2 * (
        v2x**2 + v2y**2 - w2x**2 - w2y**2
    )
    mu = m1 * m2 / (m1 + m2)
    scale = 0.5 * (m1 + m2) * 2 * 50**2 * 2
    assert abs(lost - 0.5 * (1 - e * e) * mu * before**2) <= 1e-12 * scale
    twin = reference.pair_response(m1, m2, np.array([nx, ny]), np.zeros(2), np.array([v1x, v1y]),
                                   np.array([v2x, v2y]), e)  # fmt: skip
    np.testing.assert_allclose([w1x, w1y, w2x, w2y], np.concatenate(twin), atol=1e-11 * 50)


def test_below_the_guard_speed_a_collision_is_elastic():
    # Approaching at 1e-7 m/s along x, below a guard of 1e-6 m/s: elastic, whatever e.
    assert pair_response(1.0, 1.0, -1.0, 0.0, 1e-7, 0.0, 0.0, 0.0, 0.5, 1e-6) == (
        0.0,
        0.0,
        1e-7,
        0.0,
    )
    assert pair_response(1.0, 1.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.5, 1e-6) == (
        0.25,
        0.0,
        0.75,
        0.0,
    )
