"""Particles: shapes, broadcasting and one clear message per kind of bad input."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

from collidium import Box, InputError, Particles, Simulation


def test_scalars_broadcast_and_velocity_defaults_to_rest():
    p = Particles(position=[[0.0, 0.0], [1.0, 1.0]], mass=2.0, radius=0.1, charge=[1, -1])
    assert p.n == 2
    np.testing.assert_array_equal(p.mass, [2.0, 2.0])
    np.testing.assert_array_equal(p.velocity, np.zeros((2, 2)))
    assert p.position.dtype == np.float64 and p.charge.dtype == np.float64


@pytest.mark.parametrize(
    ("kwargs", "field", "words"),
    [
        ({"position": [[0.0, np.nan]]}, "position", "not finite"),
        ({"position": [[0.0, 0.0]], "velocity": [[np.inf, 0.0]]}, "velocity", "not finite"),
        # Light's speed, m/s, along a diagonal: Newtonian mechanics only below it.
        (
            {"position": [[0, 0], [1, 0]], "velocity": [[0, 0], [2.12e8, 2.12e8]]},
            "velocity",
            "particle 1 moves at 3e+08 m/s, not below the speed of light",
        ),
        ({"position": [[0.0, 0.0]], "velocity": [[1e300, 1e300]]}, "velocity", "at inf m/s"),
        ({"position": [[0.0, 0.0]], "mass": 0.0}, "mass", "> 0"),
        ({"position": [[0.0, 0.0]], "mass": [-1.0]}, "mass", "> 0"),
        ({"position": [[0.0, 0.0]], "radius": -0.1}, "radius", ">= 0"),
        ({"position": [[0.0, 0.0, 0.0]]}, "position", "shape"),
        ({"position": [[0.0, 0.0]], "velocity": [[1.0, 0.0], [0.0, 0.0]]}, "velocity", "shape"),
        ({"position": [[0.0, 0.0]], "charge": [1.0, 2.0]}, "charge", "1 values"),
        ({"position": [["a", 0.0]]}, "position", "not an array"),
    ],
)
def test_bad_particles_name_the_field(kwargs, field, words):
    with pytest.raises(InputError) as info:
        Particles(**kwargs)
    assert info.value.field == field
    assert words in str(info.value)
    assert "\n" not in str(info.value)


def test_overlapping_pair_is_named():
    p = Particles(position=[[0.0, 0.0], [3.0, 0.0], [3.3, 0.0]], radius=0.25)
    with pytest.raises(InputError, match="particles 1 and 2 overlap"):
        Simulation(Box(20, 20), p)


def test_overlap_allowed_when_collisions_are_off():
    p = Particles(position=[[0.0, 0.0], [0.1, 0.0]], radius=0.25)
    Simulation(Box(20, 20), p, collisions="off")


def test_particle_outside_the_vessel_is_named():
    p = Particles(position=[[0.0, 0.0], [9.9, 0.0]], radius=0.25)
    with pytest.raises(InputError, match=r"particle 1 .* outside"):
        Simulation(Box(20, 20), p)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [({"dt": 0.0}, "dt"), ({"dt": float("nan")}, "dt"), ({"collisions": "sticky"}, "collisions")],
)
def test_bad_simulation_settings_name_the_field(kwargs, field):
    with pytest.raises(InputError) as info:
        Simulation(Box(20, 20), Particles(position=[[0.0, 0.0]]), **kwargs)
    assert info.value.field == field


def test_a_scalar_property_is_stored_once_and_read_only():
    p = Particles(np.zeros((1000, 2)), mass=2.0, radius=[0.1] * 1000)
    assert p.mass.shape == (1000,) and p.mass.strides == (0,)  # one value, 8 bytes
    assert p.mass.base is not None and p.mass.base.nbytes == 8
    with pytest.raises(ValueError, match="read-only"):
        p.mass[0] = 3.0
    p.radius[0] = 0.2  # given as an array: each particle's own, writable
    assert p.radius[:2].tolist() == [0.2, 0.1]


def test_assigned_properties_are_checked_and_scalars_shared():
    p = Particles(np.zeros((3, 2)))
    p.radius = 0.4
    assert p.radius.strides == (0,) and p.radius.tolist() == [0.4] * 3
    mass = p.mass.copy()
    mass[1] = 5.0
    p.mass = mass
    assert p.mass.tolist() == [1.0, 5.0, 1.0] and p.mass.flags.writeable
    for name, value, words in [("mass", [1, -1, 1], "> 0"), ("charge", np.nan, "not finite"),
                               ("radius", [1, 2], "3 values")]:  # fmt: skip
        with pytest.raises(InputError) as info:
            setattr(p, name, value)
        assert info.value.field == name and words in str(info.value)


@pytest.mark.parametrize(
    "duplicate", [Particles.copy, copy.deepcopy, lambda p: pickle.loads(pickle.dumps(p))]
)
def test_copies_keep_shared_values_shared_and_arrays_independent(duplicate):
    p = Particles([[0.0, 0.0], [1.0, 0.0]], mass=3.0, charge=[1.0, -1.0])
    q = duplicate(p)
    assert q.mass.strides == (0,) and q.mass.tolist() == [3.0, 3.0]
    assert q.charge.flags.writeable and q.charge.tolist() == [1.0, -1.0]
    q.position[0, 0] = 9.0
    q.charge[0] = 2.0
    assert p.position[0, 0] == 0.0 and p.charge[0] == 1.0
