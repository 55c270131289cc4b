"""Initial-condition generators: placement, velocities, charges, the pool rack."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collidium import initial
from collidium.errors import InputError
from collidium.initial import (
    balanced_charges,
    hexagonal_positions,
    random_positions,
    rhombus_rack,
    uniform_velocities,
)
from collidium.vessels import Box, Partition


def min_gap(position: np.ndarray, radius: np.ndarray) -> float:
    """Smallest ``distance - (r_i + r_j)`` over all pairs (brute force)."""
    delta = position[:, None, :] - position[None, :, :]
    distance = np.sqrt((delta**2).sum(-1))
    gap = distance - (radius[:, None] + radius[None, :])
    np.fill_diagonal(gap, np.inf)
    return float(gap.min())


@pytest.mark.parametrize(
    ("n", "radius", "width", "height"), [(200, 0.25, 20, 20), (300, 0.4, 30, 12)]
)
def test_random_positions_inside_and_apart(n, radius, width, height):
    position = random_positions(n, radius, Box(width, height), np.random.default_rng(5))
    assert position.shape == (n, 2)
    assert (np.abs(position[:, 0]) <= width / 2 - radius).all()
    assert (np.abs(position[:, 1]) <= height / 2 - radius).all()
    assert min_gap(position, np.full(n, radius)) >= 0


def test_random_positions_deterministic_given_the_generator():
    a = random_positions(100, 0.25, Box(20, 20), np.random.default_rng(3))
    b = random_positions(100, 0.25, Box(20, 20), np.random.default_rng(3))
    c = random_positions(100, 0.25, Box(20, 20), np.random.default_rng(4))
    assert a.tobytes() == b.tobytes()
    assert not np.array_equal(a, c)


def test_random_positions_fill_the_box_uniformly():
    position = random_positions(4000, 0.05, Box(20, 20), np.random.default_rng(0))
    # each quadrant holds 1000 +- 3 sigma (binomial sigma = sqrt(4000 / 4 * 3 / 4) ~ 27)
    counts = np.histogram2d(position[:, 0], position[:, 1], bins=2, range=[[-10, 10], [-10, 10]])
    assert np.all(np.abs(counts[0] - 1000) < 3 * 27.4)


def test_random_positions_avoid_existing_disks():
    big = np.array([[0.0, 0.0], [5.0, 5.0]])
    position = random_positions(
        300, 0.25, Box(20, 20), np.random.default_rng(1), existing=big, existing_radius=[3.0, 2.0]
    )
    everything = np.concatenate([big, position])
    radii = np.concatenate([[3.0, 2.0], np.full(300, 0.25)])
    assert min_gap(everything, radii) >= 0


def test_random_positions_too_dense_names_the_field():
    with pytest.raises(InputError) as info:
        random_positions(3000, 0.25, Box(20, 20), np.random.default_rng(0), field="particles.2.n")
    assert info.value.field == "particles.2.n"
    assert "too dense" in info.value.reason


def test_random_positions_gives_up_after_bounded_batches():
    # below the hexagonal limit but far above random close packing: cannot be placed at random
    with pytest.raises(InputError, match="too dense"):
        random_positions(1400, 0.25, Box(20, 20), np.random.default_rng(0), max_batches=20)


def test_random_positions_point_particles_and_empty():
    assert random_positions(0, 0.25, Box(20, 20), np.random.default_rng(0)).shape == (0, 2)
    points = random_positions(50, 0.0, Box(2, 2), np.random.default_rng(0))
    assert points.shape == (50, 2) and (np.abs(points) <= 1).all()


def test_uniform_velocities_range_and_determinism():
    v = uniform_velocities(1000, 10.0, np.random.default_rng(2))
    assert v.shape == (1000, 2)
    assert (np.abs(v) <= 10).all() and np.abs(v).max() > 9.5
    assert v.tobytes() == uniform_velocities(1000, 10.0, np.random.default_rng(2)).tobytes()
    with pytest.raises(InputError):
        uniform_velocities(3, -1.0, np.random.default_rng(2))


@pytest.mark.parametrize("n", [0, 1, 2, 7, 200])
def test_balanced_charges_counts(n):
    q = balanced_charges(n, 1.5, np.random.default_rng(0))
    assert q.shape == (n,)
    assert (q == 1.5).sum() == n - n // 2
    assert (q == -1.5).sum() == n // 2


def test_balanced_charges_are_shuffled():
    q = balanced_charges(200, 1.0, np.random.default_rng(0))
    assert not (q[:100] == 1).all()


def test_rhombus_rack_shape_and_spacing():
    r = 0.25
    rack = rhombus_rack((3.0, 0.0), 15, r, gap=0.01)
    assert rack.shape == (224, 2)
    assert rhombus_rack((3.0, 0.0), 15, r, back_tip=True).shape == (225, 2)
    assert tuple(rack[0]) == (3.0, 0.0)
    assert rack[:, 0].min() == 3.0  # apex is the leftmost ball, pointing left
    spacing = 2 * r * (1 + 0.005)
    delta = rack[:, None, :] - rack[None, :, :]
    distance = np.sqrt((delta**2).sum(-1))
    np.fill_diagonal(distance, np.inf)
    assert distance.min() == pytest.approx(spacing, rel=1e-12)
    # hexagonal packing: interior balls have 6 neighbours at the spacing
    neighbours = (np.abs(distance - spacing) < 1e-9).sum(1)
    assert neighbours.max() == 6
    columns = np.unique(np.round(rack[:, 0], 9), return_counts=True)[1]
    assert list(columns) == [*range(1, 16), *range(14, 1, -1)]
    assert np.isclose(rack[:, 1].max(), 7 * spacing) and np.isclose(rack[:, 1].mean(), 0)
    assert math.isclose(rack[:, 0].max(), 3.0 + 27 * spacing * math.sqrt(3) / 2)


def test_random_positions_in_a_region_fill_only_that_rectangle_of_the_vessel():
    box = Box(40, 20, partitions=[Partition("divider", (0.0, -10.0), (0.0, 10.0), gap=2.0)])
    region = [[-20.0, -10.0], [0.0, 10.0]]
    position = random_positions(2000, 0.1, box, np.random.default_rng(2), region=region)
    assert (position[:, 0] <= -0.1).all() and (position[:, 0] >= -19.9).all()
    assert (np.abs(position[:, 1]) <= 9.9).all()
    assert (
        min_gap(position, np.full(2000, 0.1)) >= 0
        and not box.outside(position, np.full(2000, 0.1)).any()
    )
    # Uniform over the region: each half of it holds 1000 +- 3 sigma (binomial sigma ~ 22).
    assert abs(int((position[:, 1] > 0).sum()) - 1000) < 3 * 22.4


def test_a_region_that_leaves_no_room_is_refused_naming_it():
    with pytest.raises(InputError) as info:
        random_positions(10, 0.5, Box(20, 20), np.random.default_rng(0), region=[[9.8, 0], [12, 1]],
                         field="particles.1.n")  # fmt: skip
    assert info.value.field == "particles.1.region" and "no room" in info.value.reason


def test_placement_grid_covers_the_region_not_the_vessel(rng):
    """Disks placed in a 10 m corner of a 10 km box are looked up in cells over that corner
    (over the whole box they would all share a few cells, and placement would be quadratic)."""
    vessel = Box(1e4, 1e4)
    region = [[-5e3, -5e3], [-4990.0, -4990.0]]
    position = random_positions(2000, 0.05, vessel, rng, region=region)
    assert (position >= -5e3 + 0.05).all() and (position <= -4990.0 - 0.05).all()
    low, high = initial._candidate_box(vessel, 0.05, region, "particles.n")
    corner, cell, ncx, ncy = initial._placement_grid(np.zeros((0, 2)), low, high, 0.05, 2000)
    np.testing.assert_array_equal(corner, low)
    assert 0.1 <= cell <= 0.3 and ncx * ncy >= 1000


@pytest.mark.parametrize("packing", [0.3, 0.7, 0.9])
def test_hexagonal_positions_pack_the_plane_as_asked(packing):
    """Nearest neighbours one lattice spacing apart, so the disks cover ``packing`` of the
    plane (a hexagonal cell of area sqrt(3)/2 a^2 per disk), none overlapping, all inside."""
    vessel, radius = Box(20.0, 20.0), 0.25
    position = hexagonal_positions(vessel, radius, packing)
    spacing = radius * math.sqrt(2 * math.pi / (math.sqrt(3) * packing))
    gaps = np.linalg.norm(position[:, None] - position[None, :], axis=2)
    np.fill_diagonal(gaps, np.inf)
    np.testing.assert_allclose(gaps.min(axis=1), spacing, rtol=1e-12)
    assert math.pi * radius**2 / (math.sqrt(3) / 2 * spacing**2) == pytest.approx(packing)
    assert vessel.outside(position, np.full(len(position), radius)).size == 0
    assert len(position) > 0.8 * packing * 400 / (math.pi * radius**2)
