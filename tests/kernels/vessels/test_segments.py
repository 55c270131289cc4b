"""The segment kernels (polygon edges and corners, partitions): time to contact equal to its twin
and ending exactly a radius from the segment, the snap and normal at contact, and the outside
test."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from collidium.kernels import reference
from collidium.kernels.vessels.segments import element_delay, reaches_outside, touch
from collidium.vessels import Partition, Polygon
from collidium.vessels.partitions import distances, segment_table

#: A slanted segment and a point.
TABLE = segment_table(np.array([[-1.0, -2.0], [0.5, 0.5]]), np.array([[3.0, 1.0], [0.5, 0.5]]),
                      np.array([0, 1]), boundary=False)  # fmt: skip


@settings(max_examples=400, deadline=None)
@given(
    st.floats(-6, 6), st.floats(-6, 6), st.floats(0.0, 2 * math.pi), st.floats(1e-3, 20),
    st.one_of(st.just(0.0), st.floats(1e-3, 0.8)), st.sampled_from([0, 1]),
)  # fmt: skip
@example(0.0, 0.0, 0.0, 17.0, 0.5, 1)  # a path tangent to the point: the kernel touches
@example(-2.875, 0.0, 0.0, 1.0, 0.5, 1)  # tangent to the point 3.4 m ahead: a double root
def test_element_delay_equals_its_twin_and_ends_a_radius_away(x, y, heading, speed, r, e):
    start = np.array([x, y])
    if distances(start[None], TABLE[e : e + 1])[0, 0] <= r:
        return  # the disk must start clear of the segment
    # A disk of radius 0 meets a point only on a path exactly through it: a double root of
    # zero width, which round-off makes or breaks (the segment that ends there meets it all the
    # same).
    assume(not (r == 0.0 and e == 1))
    velocity = np.array([speed * math.cos(heading), speed * math.sin(heading)])
    delay = element_delay(x, y, *velocity, r, TABLE, e)
    twin = reference.segment_delay(start, velocity, r, TABLE[e])
    if math.isinf(twin) or math.isinf(delay):
        if math.isinf(twin) != math.isinf(delay):
            # Only a graze may split them: a path tangent to the element is a double root of
            # zero width, which round-off makes or breaks. There the disk touches, moving along.
            found = delay if math.isfinite(delay) else twin
            at = start + velocity * found
            assert abs(distances(at[None], TABLE[e : e + 1])[0, 0] - r) <= 1e-10
            _, _, nx, ny = touch(*at, *velocity, r, TABLE, e)
            assert abs(velocity @ [nx, ny]) <= 1e-6 * speed
        return
    # A linear or quadratic root: equal to round-off relative to the time to cross 12 m. Near a
    # graze of a point the root is nearly double: the discriminant b^2 - 4ac cancels to round-off
    # of b^2, whose square root leaves sqrt(eps) of the time to reach the point (an end).
    reach = max(math.dist(start, TABLE[e, :2]), math.dist(start, TABLE[e, 2:4])) + r
    graze = 4.0 * math.sqrt(np.finfo(float).eps) * reach
    assert abs(delay - twin) <= 1e-11 * (1.0 + 12.0 / speed) + graze / speed
    at = start + velocity * delay
    assert abs(distances(at[None], TABLE[e : e + 1])[0, 0] - r) <= 1e-10
    cx, cy, nx, ny = touch(*at, *velocity, r, TABLE, e)
    assert abs(distances(np.array([[cx, cy]]), TABLE[e : e + 1])[0, 0] - r) <= 1e-14 * 10
    assert abs(math.hypot(nx, ny) - 1.0) <= 1e-15
    assert velocity @ [nx, ny] >= -1e-7 * speed  # moving into it, or grazing a point


def test_a_disk_moving_along_a_segment_or_away_never_touches_it():
    assert math.isinf(element_delay(-2.0, 0.0, 4.0, 3.0, 0.5, TABLE, 0))  # parallel to it
    assert math.isinf(element_delay(0.0, 3.0, 0.0, 1.0, 0.5, TABLE, 0))  # moving away
    assert math.isinf(element_delay(5.0, 5.0, 1.0, 0.0, 0.5, TABLE, 1))  # away from the point


def test_the_outside_test_sees_edges_reflex_corners_and_partitions():
    shape = Polygon([[0, 0], [10, 0], [10, 4], [4, 4], [4, 10], [0, 10]],
                    partitions=[Partition("p", (1.0, 0.0), (1.0, 3.0))])  # fmt: skip
    table = shape.segments()
    points = np.array([[2.0, 2.0], [7.0, 7.0], [3.7, 3.7], [1.3, 2.0], [1.3, 3.3], [0.5, 9.5]])
    got = [reaches_outside(x, y, 0.5, 1e-9, table) for x, y in points]
    assert got == [False, True, True, True, True, False]
    assert got == [i in set(shape.outside(points, np.full(6, 0.5))) for i in range(6)]
