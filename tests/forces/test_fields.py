"""A uniform electric field: the projectile of the seed's future work, on the charges alone."""

from __future__ import annotations

import numpy as np
import pytest

import collidium as cd
from collidium import Box, Particles, UniformField


def test_a_charge_moving_along_a_charged_plate_follows_the_parabola():
    """A +2 C, 0.5 kg charge launched at (4, 6) m/s over a plate that pulls it down with
    E = (0, -3) N/C: acceleration q E / m = (0, -12) m/s^2; it comes back to its height after
    2 vy / a = 1 s, a range 2 vx vy / a = 4 m further, to round-off."""
    start = np.array([-5.0, 0.0])
    particles = Particles([start], velocity=[[4.0, 6.0]], mass=0.5, charge=2.0)
    sim = cd.Simulation(Box(20, 20), particles, forces=[UniformField(E=(0.0, -3.0))], dt=0.01)
    sim.run(time=1.0)
    np.testing.assert_allclose(
        sim.particles.position[0], start + np.array([4.0, 0.0]), rtol=0, atol=1e-13
    )
    np.testing.assert_allclose(sim.particles.velocity[0], [4.0, -6.0], rtol=0, atol=1e-13)


def test_the_field_moves_charges_only_and_each_by_its_charge_over_mass():
    particles = Particles(
        [[-4.0, 0.0], [0.0, 0.0], [4.0, 0.0]], mass=[1.0, 2.0, 1.0], charge=[1.0, 1.0, 0.0]
    )
    sim = cd.Simulation(Box(20, 20), particles, forces=[UniformField(E=(2.0, 0.0))], dt=0.01)
    start = sim.energy().total
    sim.run(time=0.5)
    # x = x0 + (q E / m) t^2 / 2: 0.25 m for q/m = 1, 0.125 m for 1/2, 0 for the neutral one.
    np.testing.assert_allclose(sim.particles.position[:, 0], [-3.75, 0.125, 4.0], atol=1e-14)
    assert sim.energy().total == pytest.approx(start, abs=1e-13)
