"""Cell grids: the window they cover (`cells.grid_window`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from collidium.kernels import cells


def test_bounding_box_holds_every_point(rng):
    position = rng.normal(0.0, 3.0, (500, 2))
    x0, y0, x1, y1 = cells.bounding_box(position)
    np.testing.assert_array_equal([x0, y0], position.min(axis=0))
    np.testing.assert_array_equal([x1, y1], position.max(axis=0))


def test_window_of_a_cluster_covers_its_surroundings_only(rng):
    """Disks in a corner of a 1 km box: the window holds them all with a margin of a quarter of
    their spread and a diameter, and is a tiny part of the box."""
    n = cells.WINDOW_FROM
    position = rng.uniform(-499.0, -479.0, (n, 2))
    window = cells.grid_window(position, 0.1, (1000.0, 1000.0), periodic=False)
    spread = position.max(axis=0) - position.min(axis=0)
    reach = 0.1 + cells.WINDOW_MARGIN * spread.max()
    np.testing.assert_allclose(window[0], np.maximum(position.min(axis=0) - reach, -500.0))
    np.testing.assert_allclose(window[1], position.max(axis=0) + reach)
    assert window[0, 0] == -500.0  # cut at the vessel's bounding box
    assert np.prod(window[1] - window[0]) < 1e-3 * 1000.0**2


@pytest.mark.parametrize(
    ("n", "periodic"), [(cells.WINDOW_FROM, True), (cells.WINDOW_FROM - 1, False), (0, False)]
)
def test_window_is_the_vessel_when_periodic_or_for_few_disks(rng, n, periodic):
    position = rng.uniform(-1.0, 1.0, (n, 2))
    window = cells.grid_window(position, 0.1, (100.0, 60.0), periodic)
    np.testing.assert_array_equal(window, [[-50.0, -30.0], [50.0, 30.0]])


def test_window_of_points_at_one_place_is_the_vessel():
    """Point particles all at one place leave a window of no area: the vessel's is used."""
    position = np.zeros((cells.WINDOW_FROM, 2))
    window = cells.grid_window(position, 0.0, (10.0, 10.0), periodic=False)
    np.testing.assert_array_equal(window, [[-5.0, -5.0], [5.0, 5.0]])


@pytest.mark.parametrize("diameter", [5e-324, 2.2e-308, 1e-300])
def test_a_vanishing_diameter_gets_the_fewest_cells_per_particle(diameter):
    """A diameter so small that the window over it overflows float64 still gets a grid within
    the budget of about 2 cells per particle."""
    ncx, ncy = cells.grid_shape(20.0, 20.0, diameter, 20)
    assert 1 <= ncx * ncy <= 40
    assert cells.event_grid_shape(20.0, 20.0, diameter, 20) == cells.event_grid_shape(
        20.0, 20.0, 0.1, 20
    )


def test_a_small_dilute_scene_takes_smaller_cells_than_a_large_one():
    """Below `SMALL_SCENE` particles a dilute gas's event grid has up to
    `SMALL_SCENE_CELLS_PER_PARTICLE` cells a particle, from there on, under a gravity the engine
    carries or with segments up to `EVENT_CELLS_PER_PARTICLE`; no cell is narrower than a
    diameter."""

    def cells_per_particle(n: int, area_per_particle: float, **vessel: Any) -> float:
        side = math.sqrt(n * area_per_particle)
        ncx, ncy = cells.event_grid_shape(side, side, 0.5, n, **vessel)
        assert side / ncx >= 0.5 and side / ncy >= 0.5
        return ncx * ncy / n

    small, large = cells.SMALL_SCENE - 1, cells.SMALL_SCENE
    assert 0.9 * 6 < cells_per_particle(small, 100.0) <= cells.SMALL_SCENE_CELLS_PER_PARTICLE == 6
    assert 0.9 * 3 < cells_per_particle(large, 100.0) <= cells.EVENT_CELLS_PER_PARTICLE == 3
    # where a crossing costs more: under a gravity the engine carries, or with segments
    assert 0.9 * 3 < cells_per_particle(small, 100.0, falls=True) <= 3
    assert 0.9 * 3 < cells_per_particle(small, 100.0, segments=6) <= 3
    # dense: cells of one diameter, about 2.4 a particle, whatever the size
    assert cells_per_particle(small, 0.6) == pytest.approx(2.4, rel=0.02)
    assert cells_per_particle(large, 0.6) == pytest.approx(2.4, rel=0.02)
