"""Elastic response (seed eq. 7): exact cases and conservation laws."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from collidium.kernels import reference
from collidium.kernels.collision import elastic_response

finite = st.floats(-50.0, 50.0, allow_nan=False)
masses = st.floats(1e-2, 1e2, allow_nan=False)


def test_head_on_equal_masses_swap_velocities():
    v = elastic_response(1.0, 1.0, -0.5, 0.0, 5.0, 0.0, -5.0, 0.0)
    assert v == (-5.0, 0.0, 5.0, 0.0)


def test_unequal_masses_one_dimension_textbook():
    m1, m2, u1, u2 = 2.0, 0.5, 3.0, -1.0
    v1x, v1y, v2x, v2y = elastic_response(m1, m2, -1.0, 0.0, u1, 0.0, u2, 0.0)
    expected_1 = ((m1 - m2) * u1 + 2 * m2 * u2) / (m1 + m2)
    expected_2 = ((m2 - m1) * u2 + 2 * m1 * u1) / (m1 + m2)
    np.testing.assert_allclose([v1x, v2x], [expected_1, expected_2], rtol=1e-15)
    assert v1y == v2y == 0.0


def test_glancing_contact_changes_only_the_normal_component():
    # Normal along x: the y components pass through untouched.
    v1x, v1y, v2x, v2y = elastic_response(1.0, 1.0, -0.5, 0.0, 3.0, 2.0, 0.0, -1.0)
    assert (v1y, v2y) == (2.0, -1.0)
    assert (v1x, v2x) == (0.0, 3.0)


@settings(max_examples=300, deadline=None)
@given(masses, masses, finite, finite, finite, finite, finite, finite)
def test_collision_conserves_energy_and_momentum(m1, m2, nx, ny, v1x, v1y, v2x, v2y):
    if nx * nx + ny * ny < 1e-6:
        nx, ny = 1.0, 0.0
    w1x, w1y, w2x, w2y = elastic_response(m1, m2, nx, ny, v1x, v1y, v2x, v2y)
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
    got = elastic_response(m1, m2, nx, ny, v1x, v1y, v2x, v2y)
    w1, w2 = reference.elastic_response(
        m1, m2, np.array([nx, ny]), np.zeros(2), np.array([v1x, v1y]), np.array([v2x, v2y])
    )
    np.testing.assert_allclose(got, [*w1, *w2], rtol=1e-12, atol=1e-12 * 50)
