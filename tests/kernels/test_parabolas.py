"""Flight on a parabola against its NumPy twins: the first contact with a line (a quadratic) and
the first crossing of a distance from a point (a quartic), and the walls and segments met under
a uniform gravity."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from collidium.kernels import parabolas, reference
from collidium.kernels.vessels import box, circle, segments

EPS = float(np.finfo(float).eps)


def approx(value: float) -> object:
    """Equal to round-off (np.roots solves an eigenvalue problem)."""
    return pytest.approx(value, rel=1e-9, abs=1e-12)


def _scale(low: float, high: float) -> st.SearchStrategy[float]:
    """Numbers of the physical scale or 0 (np.roots loses real roots of coefficients near the
    underflow limit)."""
    return st.floats(low, high).filter(lambda value: value == 0.0 or abs(value) > 1e-6)


@settings(max_examples=300, deadline=None)
@given(_scale(0.0, 10.0), _scale(-10.0, 10.0), _scale(-10.0, 10.0))
@example(0.5, 6.0, -8.553324732929468e-06)  # a contact after 1.4e6 s: terms of 8.4e6 m cancel
def test_first_contact_equals_its_twin(gap, rate, pull):
    got = parabolas.first_contact(gap, rate, pull)
    want = reference.first_contact(gap, rate, pull)
    if math.isinf(want):
        assert math.isinf(got)
    else:
        assert got == approx(want)
        # The gap closes at the contact, to the round-off of the largest of its three terms
        # (a few eps of each, from evaluating them and from the root's own last bits).
        terms = (gap, rate * got, 0.5 * pull * got * got)
        assert abs(sum(terms)) <= 16 * EPS * max(abs(term) for term in terms)


def test_first_contact_of_a_falling_body_and_of_straight_paths():
    # A gap of 2 m closed by a pull of 4 m/s^2 from rest: t = sqrt(2 gap / pull) = 1 s.
    assert parabolas.first_contact(2.0, 0.0, -4.0) == 1.0
    assert math.isinf(parabolas.first_contact(2.0, 1.0, 0.0))  # opening, no pull
    assert math.isinf(parabolas.first_contact(2.0, -1.0, 1.0))  # turns back before touching
    assert parabolas.first_contact(3.0, -0.7, 0.0) == 3.0 / 0.7  # a straight path, exactly


def _body() -> st.SearchStrategy[tuple[float, ...]]:
    """A position within 3 m of the origin, a velocity and an acceleration of the scale of 1 to
    10 (not both components of the acceleration near 0)."""
    return st.tuples(
        *(st.floats(-3.0, 3.0) for _ in range(2)),
        *(_scale(-10.0, 10.0) for _ in range(4)),
    ).filter(lambda b: math.hypot(b[4], b[5]) > 1e-3)


def _simple_roots(p, v, g, reach) -> bool:
    """Whether every real root of the quartic is simple by a margin (a graze, a nearly double
    root, carries sqrt(eps) of its time: `test_a_graze_is_found_to_the_square_root_of_eps`)."""
    quartic = [g @ g / 4, v @ g, v @ v + p @ g, 2 * p @ v, p @ p - reach**2]
    roots = np.roots(quartic)
    scale = 1.0 + np.abs(roots).max()
    if any(1e-12 * scale < abs(r.imag) < 1e-3 * scale for r in roots):
        return False
    real = np.sort(roots[np.abs(roots.imag) <= 1e-12 * scale].real)
    return bool(np.all(np.diff(real) > 1e-3 * scale))


@settings(max_examples=300, deadline=None)
@given(_body(), st.floats(0.5, 6.0), st.booleans())
def test_distance_crossing_equals_its_twin(body, reach, outward):
    p, v, g = np.array(body[:2]), np.array(body[2:4]), np.array(body[4:])
    distance = float(np.linalg.norm(p))
    if (distance > reach) == outward or distance == 0.0:  # start on the side it crosses from
        direction = p / distance if distance > 1e-6 else np.array([1.0, 0.0])
        p = direction * (0.5 if outward else 2.0) * reach
    assume(abs(float(np.linalg.norm(p)) - reach) > 1e-3)
    assume(_simple_roots(p, v, g, reach))
    got = parabolas.distance_crossing(*p, *v, *g, reach, outward, math.inf)
    want = reference.distance_crossing(p, v, g, reach, outward)
    if math.isinf(want):
        assert math.isinf(got)
        return
    assert got == pytest.approx(want, rel=1e-8, abs=1e-12)
    x = p + v * got + 0.5 * g * got * got
    size = max(np.abs(p).max() + np.abs(v * got).max() + np.abs(0.5 * g * got * got).max(), 1.0)
    assert abs(np.linalg.norm(x) - reach) <= 64 * EPS * size


# The arguments are floats, as the engine passes them: integers would compile the kernel again.
def test_an_outward_crossing_must_come_and_an_inward_one_may_not():
    # Dropped from the centre of a circle of reach 1 under g = 1: |y| = t^2 / 2 = 1 at sqrt(2).
    assert parabolas.distance_crossing(
        0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 1.0, True, math.inf
    ) == pytest.approx(math.sqrt(2.0), rel=1e-15)
    # Thrown up past a point 2 m to the side, never within 1 m of it.
    assert math.isinf(
        parabolas.distance_crossing(-2.0, 0.0, 0.0, 1.0, 0.0, -1.0, 1.0, False, math.inf)
    )
    # A horizon before the crossing: none found.
    assert math.isinf(parabolas.distance_crossing(0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 1.0, True, 1.0))


def test_a_body_across_moving_on_gets_zero_and_one_moving_back_gets_its_turn():
    # A hair outside the rim and moving out: at once.
    assert (
        parabolas.distance_crossing(1.0 + 1e-15, 0.0, 1.0, 0.0, 0.0, -1.0, 1.0, True, math.inf) == 0
    )
    # A hair outside, moving in, but pulled out again before getting inside: when it turns.
    turn = parabolas.distance_crossing(1.0 + 1e-12, 0.0, -1e-7, 0.0, 1.0, 0.0, 1.0, True, math.inf)
    assert turn == pytest.approx(1e-7, rel=1e-6)  # v + g t = 0


def test_a_graze_is_found_to_the_square_root_of_eps():
    """A body whose parabola just touches the reach: the double root is only defined to
    sqrt(eps) of its time, as for straight paths."""
    # Thrown level at (0, 0.5) under g = (0, -1), inward towards a point at the origin whose
    # reach 0.5 - h is first touched at the top: t = 0 is the apex, so aim from earlier.
    t_apex = 2.0
    p = np.array([-3.0 * t_apex, 0.5 - 0.5 * t_apex**2])
    v = np.array([3.0, t_apex])
    got = parabolas.distance_crossing(*p, *v, 0.0, -1.0, 0.5, False, math.inf)
    x = p + v * got + 0.5 * np.array([0.0, -1.0]) * got * got
    assert abs(got - t_apex) <= 4 * math.sqrt(EPS) * t_apex
    assert np.linalg.norm(x) <= 0.5 * (1 + 4 * math.sqrt(EPS))


def _root_precision(body, half, delay, wall) -> float:
    """The relative precision of a box wall's contact time: the round-off of the position over
    the normal speed there, and for a graze (a double root, the normal speed near 0) sqrt(eps)
    (`test_a_graze_is_found_to_the_square_root_of_eps`)."""
    if not math.isfinite(delay) or delay == 0.0:
        return 1e-12
    x, y, vx, vy, gx, gy = body
    axis = wall // 2
    v, g = (vx, vy)[axis], (gx, gy)[axis]
    position = abs((x, y)[axis]) + half[axis] + (abs(v) + abs(g) * delay) * delay
    speed = abs(v + g * delay)
    simple = 16 * EPS * position / (speed * delay) if speed > 0.0 else math.inf
    return max(1e-12, min(4 * math.sqrt(EPS), simple))


@settings(max_examples=200, deadline=None)
@given(_body(), st.floats(0.0, 0.5))
@example((0.0, 0.0, 10.0, 0.0, -9.999999999999998, 0.0), 0.0)  # grazes the right wall at t = 1
def test_box_walls_under_gravity_equal_their_twin(body, r):
    half = np.array([5.0, 4.0])
    x, y, vx, vy, gx, gy = body
    delay, wall = box.wall_delay(x, y, vx, vy, r, *half, gx, gy)
    twin_delay, twin_wall = reference.box_wall_delay(
        np.array([x, y]), np.array([vx, vy]), r, half, np.array([gx, gy])
    )
    precision = _root_precision(body, half, twin_delay, twin_wall)
    assert delay == pytest.approx(twin_delay, rel=precision, abs=1e-15)
    if wall != twin_wall:  # a tie to round-off between two walls
        return
    axis = wall // 2
    at = (x, y)[axis] + ((vx, vy)[axis] + 0.5 * (gx, gy)[axis] * delay) * delay
    assert abs(at - box.contact_coordinate(wall, r, *half)) <= 1e-9


@settings(max_examples=200, deadline=None)
@given(_body(), st.floats(0.0, 0.5))
def test_the_rim_under_gravity_equals_its_twin(body, r):
    rim = 5.0
    p, v, g = np.array(body[:2]), np.array(body[2:4]), np.array(body[4:])
    assume(_simple_roots(p, v, g, rim - r))
    delay, contact = circle.wall_delay(*p, *v, r, rim, *g)
    twin, twin_contact = reference.circle_wall_delay(p, v, r, rim, g)
    assert contact == twin_contact == 0  # it must come
    assert delay == pytest.approx(twin, rel=1e-8, abs=1e-12)


TABLE = np.array([
    [-2.0, -1.0, 2.0, -1.0, 1.0, 0.0, 4.0, 0, 0],  # a shelf
    [1.0, 2.0, 1.0, 2.0, 1.0, 0.0, 0.0, 1, 0],  # a point
])  # fmt: skip


@settings(max_examples=300, deadline=None)
@given(_body(), st.floats(0.05, 0.5), st.sampled_from([0, 1]))
def test_segments_under_gravity_equal_their_twin(body, r, e):
    p, v, g = np.array(body[:2]), np.array(body[2:4]), np.array(body[4:])
    start = p + np.array([0.0, 3.0])
    row = TABLE[e]
    assume(segments.distance(*start, TABLE, e) > r + 1e-3)
    if e == 1:
        assume(_simple_roots(start - row[:2], v, g, r))
    else:
        # Not near a graze of the line, nor near its ends (where the ends' points take over).
        for level in (r, -r):
            d0, w, pull = start[1] - row[1], v[1], g[1]
            disc = w * w - 2 * pull * (d0 - level)
            assume(abs(disc) > 1e-6 * (w * w + abs(pull * d0)))
    got = segments.element_delay(*start, *v, r, TABLE, e, *g)
    want = reference.segment_delay(start, v, r, row, g)
    if math.isinf(want):
        assert math.isinf(got)
        return
    assert got == pytest.approx(want, rel=1e-8, abs=1e-12)
    x = start + v * got + 0.5 * g * got * got
    assert segments.distance(*x, TABLE, e) == pytest.approx(r, rel=1e-7)
