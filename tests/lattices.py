"""Disk placements that tests share: ``from lattices import jittered_lattice`` (pytest puts
``tests/`` on the path with its conftest.py; a ``from conftest import`` would find whichever
conftest.py was imported first, tests/viewer's when a run starts there)."""

from __future__ import annotations

import numpy as np


def jittered_lattice(n_side: int, width: float, radius_max: float, rng: np.random.Generator):
    """Centres on an n_side x n_side lattice, each moved at random within its own lattice cell so
    that no two disks of radius <= radius_max overlap and all lie inside the box."""
    spacing = width / n_side
    room = 0.5 * spacing - radius_max
    assert room > 0
    grid = (np.arange(n_side) + 0.5) * spacing - width / 2
    centres = np.array([(x, y) for y in grid for x in grid])
    return centres + rng.uniform(-room, room, centres.shape)
