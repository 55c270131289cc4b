"""The magnetic field: cyclotron orbits (radius and period), speeds kept to round-off."""

from __future__ import annotations

import math

import numpy as np
import pytest

import collidium as cd
from collidium import Box, MagneticField, Particles

#: One ion: m = 1 kg, q = 1 C, speed 2 m/s, in B = pi/4 T: omega = pi/4 rad/s, period 8 s,
#: radius m v / (q B) = 8 / pi m, circling clockwise about the origin.
OMEGA = math.pi / 4
SPEED = 2.0
RADIUS = SPEED / OMEGA


def _ion(**options) -> cd.Simulation:
    particles = Particles([[0.0, RADIUS]], velocity=[[SPEED, 0.0]], charge=1.0, radius=0.1)
    return cd.Simulation(Box(20, 20), particles, forces=[MagneticField(B=OMEGA)], **options)


def _orbit(sim: cd.Simulation, time: float) -> np.ndarray:
    """Positions (steps, 2) after each step over ``time``."""
    steps = round(time / sim.dt)
    out = np.empty((steps, 2))
    for k in range(steps):
        out[k] = sim.run(steps=1).particles.position[0]
    return out


def _circle(path: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre and radius of positions spread evenly over whole turns."""
    centre = path.mean(axis=0)
    return centre, float(np.mean(np.hypot(*(path - centre).T)))


def test_cyclotron_radius_is_m_v_over_q_b_to_second_order():
    """The split flow (half a turn, a straight drift, half a turn) puts the ion, step after
    step, on the corners of a regular polygon of side ``v h`` turning by ``theta = omega h``:
    a circle of radius ``r theta / (2 sin(theta / 2)) = r (1 + theta^2 / 24 + ...)``."""
    for dt in (0.04, 0.02):
        _, radius = _circle(_orbit(_ion(dt=dt, integrator="fixed"), 8.0))
        theta = OMEGA * dt
        assert radius / RADIUS == pytest.approx(theta / (2 * math.sin(theta / 2)), abs=1e-12)
        assert radius / RADIUS - 1 == pytest.approx(theta**2 / 24, rel=1e-3)


def test_cyclotron_period_is_2_pi_m_over_q_b():
    """After half a period the velocity is reversed, after a whole one the ion is back where it
    started (a step turns the velocity by exactly omega h; the radius errs as above)."""
    sim = _ion(dt=0.01)
    sim.run(time=4.0)
    np.testing.assert_allclose(sim.particles.velocity[0], [-SPEED, 0.0], atol=1e-12)
    sim.run(time=4.0)
    np.testing.assert_allclose(sim.particles.position[0], [0.0, RADIUS], atol=1e-12 * RADIUS)


def test_adaptive_substeps_follow_the_cyclotron_frequency():
    """With the default tolerance a substep turns the velocity by at most ``tolerance``
    radians: the radius errs by at most ``tolerance^2 / 24``."""
    sim = _ion(dt=0.01)
    _, radius = _circle(_orbit(sim, 8.0))
    assert 0.0 < radius / RADIUS - 1 <= sim.tolerance**2 / 24


@pytest.mark.slow
def test_speed_is_kept_to_round_off_with_walls_and_collisions():
    """Ions of both signs and several masses bouncing in a small box for 20 s. Each half
    substep turns every velocity once, rounding its length by about one unit in the last place
    (the same angle, so not at random): the energy may move by that much per turn, no more."""
    rng = np.random.default_rng(5)
    particles = Particles(
        [[-3.0, -3.0], [3.0, 3.0], [-3.0, 3.0], [3.0, -3.0]], velocity=rng.normal(0, 2, (4, 2)),
        mass=[1.0, 2.0, 3.0, 0.5], charge=[1.0, -1.0, 2.0, -0.5], radius=0.5,
    )  # fmt: skip
    sim = cd.Simulation(Box(10, 10), particles, forces=[MagneticField(B=1.5)], dt=0.01)
    start = sim.energy().total
    sim.run(time=20.0)
    assert sim.counters.pair_collisions > 0 and sim.counters.wall_collisions > 0
    turns = 2 * sim.steps * sim._integrator.substeps  # the same count in every step here
    fastest = 1.5 * 0.01 / sim.tolerance  # the fastest omega dt over the tolerance
    assert turns >= 2 * 2000 * 2 ** math.ceil(math.log2(fastest))
    assert sim.energy().total == pytest.approx(start, rel=turns * np.finfo(float).eps)
    assert sim.force_heat() == 0.0


def test_a_neutral_particle_flies_straight():
    particles = Particles([[0.0, 0.0]], velocity=[[1.0, 0.5]], charge=0.0)
    sim = cd.Simulation(Box(20, 20), particles, forces=[MagneticField(B=3.0)], dt=0.01)
    sim.run(time=2.0)
    np.testing.assert_allclose(sim.particles.position[0], [2.0, 1.0], rtol=1e-13)
