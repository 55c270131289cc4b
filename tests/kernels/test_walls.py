"""Wall reflection: exact mirror of the normal component, folding equal to bounce-by-bounce."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from collidium.kernels import reference
from collidium.kernels.walls import drift_periodic, drift_reflecting, fold


def test_wall_mirrors_the_normal_component():
    position = np.array([[9.0, 0.0]])
    velocity = np.array([[4.0, 3.0]])
    hits = np.zeros(4, dtype=np.int64)
    impulse = np.zeros(4)
    drift_reflecting(
        position, velocity, np.array([0.5]), np.array([2.0]), 10.0, 10.0, 0.25, hits, impulse
    )
    # Contact at x = 9.5 after 0.125 s, then 0.125 s back: x = 9.0; y untouched.
    np.testing.assert_allclose(position, [[9.0, 0.75]], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(velocity, [[-4.0, 3.0]])
    np.testing.assert_array_equal(hits, [0, 1, 0, 0])
    np.testing.assert_array_equal(impulse, [0.0, 2 * 2.0 * 4.0, 0.0, 0.0])  # 2 m |v_x|


@settings(max_examples=200, deadline=None)
@given(st.floats(-100, 100), st.floats(-20, 20), st.floats(0.0, 0.9))
def test_fold_equals_bounce_by_bounce(x, v, r):
    lo, hi = -1.0 + r, 1.0 - r
    got = fold(x, v, lo, hi)
    want = reference.fold(x, v, lo, hi)
    assert got[1] == want[1] and got[2] == want[2]
    assert abs(got[0] - want[0]) <= 1e-12 * (1 + abs(x))
    assert lo <= got[0] <= hi


def test_periodic_drift_wraps_and_counts_images():
    position = np.array([[4.5, -4.5]])
    velocity = np.array([[2.0, -2.0]])
    image = np.zeros((1, 2), dtype=np.int64)
    drift_periodic(position, velocity, image, 10.0, 10.0, 1.0)
    np.testing.assert_allclose(position, [[-3.5, 3.5]])
    np.testing.assert_array_equal(image, [[1, -1]])
