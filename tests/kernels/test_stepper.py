"""The seed's step method and the overlap finder against their NumPy twins; the step mode's
cell sort and pair search against brute force and the seed's own search."""

from __future__ import annotations

import numpy as np
import pytest

from collidium import Box, Particles
from collidium.collisions import StepCollisions, Tally
from collidium.kernels import reference, stepper
from collidium.kernels.cells import first_overlap, grid_shape


def _crowd(rng, n=300, width=10.0):
    position = rng.uniform(-width / 2 + 0.3, width / 2 - 0.3, (n, 2))
    radius = rng.uniform(0.05, 0.3, n)
    radius[::17] = 0.0  # points never overlap anything
    return position, radius


def test_overlapping_pairs_resolved_like_the_twin(rng):
    width = 10.0
    position, radius = _crowd(rng)
    n = len(position)
    velocity = rng.normal(0, 3, (n, 2))
    mass = rng.uniform(0.5, 2, n)
    particles = Particles(position.copy(), velocity.copy(), mass=mass, radius=radius)
    tally = Tally.for_walls(4)
    StepCollisions().drift(particles, Box(width, width), 0.0, 0.0, tally)  # no flight: pairs only
    want_velocity = velocity.copy()
    want_done, want_virial = reference.step_collisions(position, want_velocity, mass, radius)
    assert tally.counts[0] == want_done > 20
    np.testing.assert_allclose(particles.velocity, want_velocity, rtol=1e-13, atol=1e-13)
    # Repulsive impulses along the line of centres: every term of the virial is positive.
    assert tally.impulse[0] > 0
    np.testing.assert_allclose(tally.impulse[0], want_virial, rtol=1e-12)


BOX_WINDOW = np.array([[-5.0, -5.0], [5.0, 5.0]])


def test_first_overlap_equals_twin(rng):
    position, radius = _crowd(rng)
    ncx, ncy = grid_shape(10.0, 10.0, 2 * radius.max(), len(radius))
    assert first_overlap(position, radius, 10.0, 10.0, False, BOX_WINDOW, ncx, ncy) == (
        reference.first_overlap(position, radius)
    )
    apart = np.array([[-1.0, 0.0], [1.0, 0.0]])
    assert first_overlap(apart, np.array([0.5, 0.5]), 10.0, 10.0, False, BOX_WINDOW, 1, 1) == (
        -1,
        -1,
    )


@pytest.mark.parametrize("scale", [0.05, 0.3])
def test_first_overlap_on_a_window_smaller_than_the_disks_spread_equals_twin(rng, scale):
    """Disks outside the grid's window fall in its edge cells (clamped): overlaps there are
    still all found."""
    position, radius = _crowd(rng)
    ncx, ncy = grid_shape(10.0 * scale, 10.0 * scale, 2 * radius.max(), len(radius))
    window = BOX_WINDOW * scale
    want = reference.first_overlap(position, radius)
    assert want != (-1, -1)
    assert first_overlap(position, radius, 10.0, 10.0, False, window, ncx, ncy) == want
    apart = position[[0, 1, 2]] * [[1.0, 1.0], [1.0, 1.0], [1.0, 1.0]]
    assert reference.first_overlap(apart, radius[:3]) == (-1, -1)
    assert first_overlap(apart, radius[:3], 10.0, 10.0, False, window, ncx, ncy) == (-1, -1)


def test_periodic_overlap_across_the_edge_is_found():
    position = np.array([[-4.9, 0.0], [4.9, 0.0], [0.0, 0.0]])
    radius = np.full(3, 0.25)
    for ncx in (1, 2, 3, 20):
        assert first_overlap(position, radius, 10.0, 10.0, True, BOX_WINDOW, ncx, ncx) == (0, 1)


def _window(width, height, scale=1.0):
    """The window of a box's cells (a share ``scale`` of the box, centred)."""
    return np.array([[-width, -height], [width, height]]) * (0.5 * scale)


def _sorted(position, radius, width, height, ncx, ncy, index=np.int32, scale=1.0):
    """The particles sorted into cells by `stepper.sort_into_cells` (cells over a share
    ``scale`` of the box)."""
    n = len(position)
    out = {
        "order": np.empty(n, index),
        "key": np.empty(n, index),
        "start": np.empty(ncx * ncy + 1, index),
        "xy": np.empty((n, 2)),
        "r": np.empty(n),
    }
    stepper.sort_into_cells(
        position, radius, False, _window(width, height, scale), ncx, ncy, np.empty(n, index),
        np.empty((n, 2)),
        np.empty(n), np.empty(ncx * ncy, index), out["order"], out["key"], out["start"],
        out["xy"], out["r"],
    )  # fmt: skip
    return out


def _cell_of(position, width, height, ncx, ncy):
    cx = np.clip(np.floor((position[:, 0] + width / 2) / (width / ncx)), 0, ncx - 1)
    cy = np.clip(np.floor((position[:, 1] + height / 2) / (height / ncy)), 0, ncy - 1)
    return (cx + ncx * cy).astype(np.int64)


def _check_sorted(cells, position, radius, width, height, ncx, ncy):
    """``width`` and ``height``: the sides of the cells' window, centred on the origin."""
    order, key, start = cells["order"], cells["key"], cells["start"]
    n = len(position)
    np.testing.assert_array_equal(np.sort(order), np.arange(n))
    np.testing.assert_array_equal(key, _cell_of(position, width, height, ncx, ncy)[order])
    np.testing.assert_array_equal(start, np.searchsorted(key, np.arange(ncx * ncy + 1)))
    np.testing.assert_array_equal(cells["xy"], position[order])
    np.testing.assert_array_equal(cells["r"], radius[order])


def test_cells_are_followed_from_step_to_step(rng):
    """`update_cells` moves the particles that changed cell and keeps a valid cell sort."""
    n, width, height, ncx, ncy = 20000, 100.0, 60.0, 90, 50
    position = rng.uniform(-0.5, 0.5, (n, 2)) * [width, height]
    radius = rng.uniform(0.0, 0.3, n)
    cells = _sorted(position, radius, width, height, ncx, ncy)
    _check_sorted(cells, position, radius, width, height, ncx, ncy)
    for step in range(4):
        position = np.clip(position + rng.normal(0, 0.05, (n, 2)), [-49.9, -29.9], [49.9, 29.9])
        if step == 2:
            radius = radius * 1.1  # new radii are read
        out = {name: np.empty_like(array) for name, array in cells.items()}
        out["r"] = cells["r"]  # last step's radii, overwritten in place
        done = _update(position, radius, step == 2, cells, out, width, height, ncx, ncy)
        assert done
        _check_sorted(out, position, radius, width, height, ncx, ncy)
        cells = out
    # Particles thrown anywhere: a full sort is the better way, and the update says so.
    scattered = rng.uniform(-0.5, 0.5, (n, 2)) * [width, height]
    out = {name: np.empty_like(array) for name, array in cells.items()}
    assert not _update(scattered, radius, False, cells, out, width, height, ncx, ncy)


def _update(position, radius, fresh, cells, out, width, height, ncx, ncy) -> bool:
    """`gather_movers` then `update_cells` from ``cells`` into ``out``, as the step mode does."""
    n = position.shape[0]
    data_xy, data_r = np.empty((n, 2)), np.empty(n)
    new_key, movers, grouped = (np.empty(n, np.int32) for _ in range(3))
    moved = np.empty(stepper.chunk_count(n), np.int64)
    stepper.gather_movers(
        position, radius, fresh, False, _window(width, height), ncx, ncy, cells["order"],
        cells["key"], cells["r"], data_xy, data_r, new_key, movers, moved,
    )  # fmt: skip
    return stepper.update_cells(
        False, ncx, ncy, cells["order"], cells["key"], data_xy, data_r, new_key, movers, grouped,
        moved, out["order"], out["key"], out["start"], out["xy"], out["r"],
    )  # fmt: skip


def _pairs(cells, ncx, ncy, width, height, periodic, general, uniform=False):
    found = np.empty(4 * 64 * 100, np.int64)
    chunks = min(4, ncy)
    r0 = cells["r"][0]
    count = stepper.overlapping_pairs(
        cells["start"], cells["order"], cells["xy"], cells["r"], uniform, r0, ncx, ncy, width,
        height, periodic, general, chunks, found, np.empty_like(found),
    )  # fmt: skip
    assert count >= 0
    return found[:count].copy()


def _all_overlaps(position, radius, width, height, periodic):
    """Every overlapping pair ``i * N + j``, i < j, by brute force (minimum image if periodic)."""
    n = len(position)
    d = position[None, :, :] - position[:, None, :]
    if periodic:
        d -= np.array([width, height]) * np.round(d / [width, height])
    sigma = radius[:, None] + radius[None, :]
    i, j = np.nonzero((np.einsum("ijk,ijk->ij", d, d) < sigma**2) & (sigma > 0)
                      & (radius[:, None] > 0) & (radius[None, :] > 0))  # fmt: skip
    keep = i < j
    return np.sort(i[keep] * n + j[keep])


@pytest.mark.parametrize("uniform", [False, True])
@pytest.mark.parametrize("periodic", [False, True])
def test_pair_search_lists_every_overlap_once(rng, periodic, uniform):
    width, height = 12.0, 9.0
    n = 600
    radius = np.full(n, 0.2) if uniform else rng.uniform(0.05, 0.35, n)
    if not uniform:
        radius[::17] = 0.0
    position = rng.uniform(-0.5, 0.5, (n, 2)) * [width, height]
    if not periodic:
        position = np.clip(position, radius[:, None] - [6, 4.5], [6, 4.5] - radius[:, None])
    position[:5, 0] = [-5.95, 5.95, -5.9, 5.9, 0.0]  # pairs across the periodic edges
    position[5:10, 1] = [-4.45, 4.45, -4.4, 4.4, 0.0]
    want = _all_overlaps(position, radius, width, height, periodic)
    assert len(want) > 100
    ncx, ncy, general = stepper.step_grid(width, height, 2 * radius.max(), n, periodic)
    assert not general
    cells = _sorted(position, radius, width, height, ncx, ncy)
    for general in (False, True):
        got = _pairs(cells, ncx, ncy, width, height, periodic, general, uniform)
        np.testing.assert_array_equal(got, want)


def test_pair_search_on_cells_over_part_of_the_box_lists_every_overlap(rng):
    """Cells over a window smaller than where the disks are (`cells.grid_window` after the
    disks spread out): those outside share its edge cells, and no overlap is missed."""
    width, height, n = 12.0, 9.0, 600
    radius = rng.uniform(0.05, 0.35, n)
    position = rng.uniform(-0.5, 0.5, (n, 2)) * [width, height]
    want = _all_overlaps(position, radius, width, height, False)
    assert len(want) > 100
    ncx, ncy, _ = stepper.step_grid(0.3 * width, 0.3 * height, 2 * radius.max(), n, False)
    assert ncx * ncy > 9
    cells = _sorted(position, radius, width, height, ncx, ncy, scale=0.3)
    _check_sorted(cells, position, radius, 0.3 * width, 0.3 * height, ncx, ncy)
    np.testing.assert_array_equal(_pairs(cells, ncx, ncy, width, height, False, False), want)


def _seed_search(position, radius, width, height, ncx, ncy):
    """The seed's search on a periodic grid, literally: each i against the particles j > i of
    its 9 neighbour cells, each cell under the shift that brings it next to i's cell."""
    cell = _cell_of(position, width, height, ncx, ncy)
    n = len(position)
    found = []
    for i in range(n):
        cx, cy = cell[i] % ncx, cell[i] // ncx
        for oy in (-1, 0, 1):
            for ox in (-1, 0, 1):
                nx, ny = cx + ox, cy + oy
                neighbour = nx % ncx + ncx * (ny % ncy)
                shift = np.array([(nx - nx % ncx) // ncx * width, (ny - ny % ncy) // ncy * height])
                for j in np.flatnonzero(cell == neighbour):
                    if j > i and radius[i] > 0 and radius[j] > 0:
                        d = position[j] + shift - position[i]
                        if d[0] * d[0] + d[1] * d[1] < (radius[i] + radius[j]) ** 2:
                            found.append(i * n + j)
    return np.sort(np.array(found, dtype=np.int64))


@pytest.mark.parametrize(("width", "height"), [(0.9, 1.5), (0.9, 6.0), (6.0, 0.9)])
def test_tiny_periodic_box_lists_pairs_as_the_seed_search_did(rng, width, height):
    """With fewer than 3 cells a side a pair can be met under two shifts, and is then listed
    twice (a side shorter than two diameters)."""
    n = 40
    radius = rng.uniform(0.2, 0.45, n)
    position = rng.uniform(-0.5, 0.5, (n, 2)) * [width, height]
    ncx, ncy, general = stepper.step_grid(width, height, 2 * radius.max(), n, True)
    assert general and min(ncx, ncy) < 3
    cells = _sorted(position, radius, width, height, ncx, ncy)
    got = _pairs(cells, ncx, ncy, width, height, True, True)
    want = _seed_search(position, radius, width, height, ncx, ncy)
    np.testing.assert_array_equal(got, want)
    assert len(np.unique(want)) < len(want)  # some pairs twice
