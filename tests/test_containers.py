"""Box: parameters, what counts as outside, wrapping and periodic images."""

from __future__ import annotations

import numpy as np
import pytest

from collidium import Box, InputError, Particles, Simulation


def test_outside_means_the_disk_reaches_past_a_wall():
    box = Box(20, 10)
    position = np.array([[9.75, 0.0], [9.76, 0.0], [0.0, -4.9], [0.0, 5.1]])
    radius = np.array([0.25, 0.25, 0.05, 0.0])
    np.testing.assert_array_equal(box.outside(position, radius), [1, 3])


def test_periodic_box_only_asks_for_the_centre_in_the_primary_cell():
    box = Box(20, 10, "periodic")
    position = np.array([[9.9, 0.0], [10.1, 0.0]])
    np.testing.assert_array_equal(box.outside(position, np.full(2, 0.25)), [1])


def test_minimum_image():
    box = Box(10, 10, "periodic")
    np.testing.assert_allclose(box.minimum_image(np.array([[9.0, -6.0]])), [[-1.0, 4.0]])
    np.testing.assert_allclose(Box(10, 10).minimum_image(np.array([[9.0, -6.0]])), [[9.0, -6.0]])


def test_disks_too_large_for_the_box_are_refused():
    with pytest.raises(InputError, match="smaller than the box side"):
        Box(1, 1).check_fits(np.array([0.6]))
    with pytest.raises(InputError, match="smaller than the box side"):
        Box(20, 0.5).check_fits(np.array([0.25]))  # would bounce between walls at no cost
    with pytest.raises(InputError, match="periodic"):
        Box(4, 4, "periodic").check_fits(np.array([1.1]))


@pytest.mark.parametrize(
    ("args", "field"),
    [((0, 10), "box.width"), ((10, -1), "box.height"), ((10, 10, "sticky"), "box.boundary")],
)
def test_bad_box_names_the_field(args, field):
    with pytest.raises(InputError) as info:
        Box(*args)
    assert info.value.field == field


def test_periodic_positions_are_wrapped_and_images_kept():
    p = Particles(position=[[12.0, -31.0]], radius=0.25)
    sim = Simulation(Box(20, 20, "periodic"), p)
    np.testing.assert_allclose(sim.particles.position, [[-8.0, 9.0]])
    np.testing.assert_array_equal(sim.particles.image, [[1, -2]])
    np.testing.assert_allclose(sim.unwrapped_position(), [[12.0, -31.0]])
