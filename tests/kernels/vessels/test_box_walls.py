"""The box's wall kernels: exact mirror of the normal component, folding equal to
bounce-by-bounce, time to a wall equal to its twin and ending at the contact point."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collidium.kernels import reference
from collidium.kernels.vessels.box import (
    contact_coordinate,
    drift_periodic,
    drift_reflecting,
    fold,
    reaches_outside,
    wall_delay,
)


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
    round_off = 1e-12 * (1 + abs(x))
    if got[2] == want[2]:
        assert got[1] == want[1]
    else:  # the path ends on a wall to round-off: one bounce more or less, the last of length 0
        assert abs(got[2] - want[2]) == 1 and got[1] == -want[1]
        assert min(got[0] - lo, hi - got[0]) <= round_off
    assert abs(got[0] - want[0]) <= round_off
    assert lo <= got[0] <= hi


def test_periodic_drift_wraps_and_counts_images():
    position = np.array([[4.5, -4.5]])
    velocity = np.array([[2.0, -2.0]])
    image = np.zeros((1, 2), dtype=np.int64)
    drift_periodic(position, velocity, image, 10.0, 10.0, 1.0)
    np.testing.assert_allclose(position, [[-3.5, 3.5]])
    np.testing.assert_array_equal(image, [[1, -1]])


@settings(max_examples=300, deadline=None)
@given(
    st.floats(-4.5, 4.5), st.floats(-2.5, 2.5), st.floats(-20, 20), st.floats(-20, 20),
    st.floats(0.0, 0.5),
)  # fmt: skip
def test_wall_delay_equals_its_twin_and_ends_at_the_contact_coordinate(x, y, vx, vy, r):
    half = np.array([5.0, 3.0])
    delay, wall = wall_delay(x, y, vx, vy, r, *half)
    twin_delay, twin_wall = reference.box_wall_delay(np.array([x, y]), np.array([vx, vy]), r, half)
    assert wall == twin_wall and (delay == twin_delay or abs(delay - twin_delay) <= 1e-12)
    if wall >= 0:
        axis = wall // 2
        at = (x, y)[axis] + (vx, vy)[axis] * delay
        assert abs(at - contact_coordinate(wall, r, *half)) <= 1e-9
        assert not reaches_outside(x + vx * delay, y + vy * delay, r, *(half * (1 + 1e-9)))


def test_a_disk_at_rest_meets_no_wall_and_one_past_a_wall_is_outside():
    assert wall_delay(0.0, 0.0, 0.0, 0.0, 0.5, 5.0, 3.0) == (np.inf, -1)
    assert reaches_outside(4.6, 0.0, 0.5, 5.0, 3.0) and not reaches_outside(4.5, 2.5, 0.5, 5.0, 3.0)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_coordinate_that_is_not_finite_is_outside(bad):
    """The audit of a box leaves the finiteness of the positions to this test
    (`collidium.kernels.audit.fails_in_box`)."""
    assert reaches_outside(bad, 0.0, 0.5, 5.0, 3.0) and reaches_outside(0.0, bad, 0.0, 5.0, 3.0)
