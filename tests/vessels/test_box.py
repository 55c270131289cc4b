"""Box: parameters, what counts as outside, wrapping, periodic images and the vessel geometry."""

from __future__ import annotations

import numpy as np
import pytest

from collidium import Box, InputError, Particles, Simulation
from collidium.vessels import VESSELS, vessel_from_dict


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
    [
        ((0, 10), "vessel.width"),
        ((10, -1), "vessel.height"),
        ((1e308, 1e308), "vessel.width"),  # its area and cell counts would overflow
        ((10, 2e12), "vessel.height"),
        ((10, 10, "sticky"), "vessel.boundary"),
    ],
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


def test_a_box_answers_the_geometry_every_layer_asks_for():
    box = Box(20, 10)
    assert box.kind == "box" and box.wall_names == ("left", "right", "bottom", "top")
    np.testing.assert_array_equal(box.bounds, [[-10, -5], [10, 5]])
    np.testing.assert_array_equal(box.size, [20, 10])
    corners = box.outline()
    # Counter-clockwise: the shoelace formula gives the area with a positive sign.
    x, y = corners[:, 0], corners[:, 1]
    assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) == pytest.approx(box.area)
    # Centres of disks of radius 0.5 stay 0.5 m from every wall.
    assert box.available_area(0.5) == pytest.approx(19 * 9)
    np.testing.assert_allclose(box.contact_lengths(0.5), [9, 9, 19, 19])
    assert box.describe() == "20 x 10 box (centred on 0, 0)"


def test_a_periodic_box_has_no_walls_and_its_centres_reach_everywhere():
    box = Box(20, 10, "periodic")
    assert box.wall_names == () and box.contact_lengths(0.5).size == 0
    assert box.available_area(0.5) == box.area == 200
    assert "periodic" in box.describe()


def test_a_vessel_comes_back_from_its_dict_and_an_unknown_shape_is_refused():
    for box in (Box(20, 10), Box(4, 6, "periodic")):
        again = vessel_from_dict(box.to_dict())
        assert isinstance(again, Box) and again.to_dict() == box.to_dict()
    assert set(VESSELS) == {"box", "circle", "polygon"}
    with pytest.raises(InputError, match=r"vessel\.shape"):
        vessel_from_dict({"shape": "torus"})
