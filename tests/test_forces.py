"""Forces as physics objects: parameters, the seed's acceleration limiter, the force field."""

from __future__ import annotations

import numpy as np
import pytest

from collidium import Box, Coulomb, InputError, Particles
from collidium.forces import ForceField


def test_limiter_caps_smoothly_and_leaves_small_accelerations_alone():
    cap = 10.0
    acceleration = np.array([[0.01, 0.0], [3.0, 4.0], [1e6, -1e6]])
    limited = acceleration.copy()
    Coulomb(max_acceleration=cap).limit(limited)
    magnitude = np.linalg.norm(limited, axis=1)
    assert (magnitude < cap).all()
    assert limited[0, 0] == pytest.approx(0.01, rel=1e-6)  # |a| << cap: unchanged to (a/cap)^2
    assert magnitude[2] == pytest.approx(cap, rel=1e-10)  # |a| >> cap: saturates at the cap
    # Direction is kept.
    np.testing.assert_allclose(limited[1] / magnitude[1], [0.6, 0.8])


def test_field_gives_acceleration_and_potential_of_a_pair():
    particles = Particles([[-2.0, 0.0], [2.0, 0.0]], mass=[1.0, 2.0], charge=[1.0, -1.0])
    field = ForceField((Coulomb(k=5.0),))
    acceleration = field.evaluate(particles, Box(20, 20))
    # |F| = k / r^2 = 5 / 16 N, towards each other; a = F / m.
    np.testing.assert_allclose(acceleration, [[5 / 16, 0.0], [-5 / 32, 0.0]], rtol=1e-15)
    assert field.potential(particles, Box(20, 20)) == pytest.approx(-5 / 4, rel=1e-15)


def test_potential_follows_moved_particles():
    particles = Particles([[-2.0, 0.0], [2.0, 0.0]], charge=[1.0, 1.0])
    box = Box(20, 20)
    field = ForceField((Coulomb(k=5.0),))
    field.evaluate(particles, box)
    particles.position[1, 0] = 3.0
    assert field.potential(particles, box) == pytest.approx(1.0, rel=1e-15)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"k": float("nan")}, "forces.coulomb.k"),
        ({"softening": -1.0}, "forces.coulomb.softening"),
        ({"max_acceleration": 0.0}, "forces.coulomb.max_acceleration"),
    ],
)
def test_bad_parameters_name_the_field(kwargs, field):
    with pytest.raises(InputError) as info:
        Coulomb(**kwargs)
    assert info.value.field == field
