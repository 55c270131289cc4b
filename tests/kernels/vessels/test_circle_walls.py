"""The circle's wall kernels: time to the rim equal to its twin and ending on the rim, and straight
flight reflected off the rim equal to bounce by bounce, keeping each disk's speed and angular
momentum about the centre."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collidium.kernels import reference
from collidium.kernels.vessels import CIRCLE
from collidium.kernels.vessels.circle import contact_point, wall_delay
from collidium.kernels.vessels.contacts import drift_responding

RIM = 5.0


@settings(max_examples=300, deadline=None)
@given(
    st.floats(0.0, 4.4), st.floats(0.0, 2 * math.pi), st.one_of(st.just(0.0), st.floats(1e-3, 20)),
    st.floats(0.0, 2 * math.pi), st.floats(0.0, 0.5),
)  # fmt: skip
def test_wall_delay_equals_its_twin_and_ends_on_the_rim(distance, angle, speed, heading, r):
    x, y = distance * math.cos(angle), distance * math.sin(angle)
    vx, vy = speed * math.cos(heading), speed * math.sin(heading)
    delay, wall = wall_delay(x, y, vx, vy, r, RIM)
    twin = reference.circle_wall_delay(np.array([x, y]), np.array([vx, vy]), r, RIM)
    assert wall == twin[1]
    if wall < 0:
        return
    # Both solve a quadratic: they agree to round-off relative to the flight across the circle.
    assert abs(delay - twin[0]) <= 1e-12 * (1.0 + 2 * RIM / math.hypot(vx, vy))
    at = np.hypot(x + vx * delay, y + vy * delay)
    assert abs(at - (RIM - r)) <= 1e-12 * RIM
    np.testing.assert_allclose(contact_point(x + vx * delay, y + vy * delay, r, RIM),
                               [x + vx * delay, y + vy * delay], atol=1e-11)  # fmt: skip


@pytest.mark.slow
def test_flight_off_the_rim_equals_bounce_by_bounce_and_keeps_speed_and_angular_momentum(rng):
    n = 200
    radius = rng.uniform(0.0, 0.3, n)
    distance = (RIM - radius) * np.sqrt(rng.uniform(0, 1, n))
    angle = rng.uniform(0, 2 * np.pi, n)
    position = np.column_stack([distance * np.cos(angle), distance * np.sin(angle)])
    velocity = rng.normal(0, 10, (n, 2))
    mass = rng.uniform(0.5, 2.0, n)
    hits, impulse, heat = np.zeros(1, np.int64), np.zeros(1), np.zeros(1)
    x, v = position.copy(), velocity.copy()
    mirror = np.zeros((1, 3))
    no_segments = np.empty((0, 9))
    drift_responding(x, v, radius, mass, 3.0, CIRCLE, RIM, RIM, RIM, no_segments, mirror, hits,
                     impulse, heat)  # fmt: skip
    twin_x, twin_v = position.copy(), velocity.copy()
    bounces = reference.circle_drift_reflecting(twin_x, twin_v, radius, RIM, 3.0)
    assert hits[0] == bounces > 3 * n  # 3 s at about 12 m/s, chords of about 8 m
    np.testing.assert_allclose(x, twin_x, atol=1e-8)
    np.testing.assert_allclose(v, twin_v, atol=1e-8)
    np.testing.assert_allclose(np.hypot(*v.T), np.hypot(*velocity.T), rtol=1e-13)
    spin = position[:, 0] * velocity[:, 1] - position[:, 1] * velocity[:, 0]
    after = x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0]
    np.testing.assert_allclose(after, spin, rtol=1e-11, atol=1e-11)
    assert (np.hypot(*x.T) + radius <= RIM * (1 + 1e-12)).all()
    assert abs(heat[0]) <= 1e-9 * np.sum(mass * np.hypot(*velocity.T) ** 2)  # a mirror
