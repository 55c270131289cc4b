"""An electric potential given on a grid: `FieldMap`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from collidium.errors import InputError
from collidium.forces.base import check_rectangle, register
from collidium.state import FloatArray, Particles
from collidium.vessels import Vessel


@register
@dataclass(frozen=True)
class FieldMap:
    """An electric potential ``phi`` (V) sampled on a regular grid, interpolated bilinearly:
    ``U_i = q_i phi(x_i)`` and ``F_i = -q_i grad phi(x_i)``, the exact gradient of the
    interpolation, so the force and the energy agree (electrodes, a lens, a field measured or
    computed elsewhere). Beyond the grid the potential keeps its edge values.

    The force of a bilinear interpolation jumps where a charge crosses a grid line, so a
    substep across one errs on the energy by O(h) rather than O(h^2): a charge rolling over
    hills 4 m wide on a 0.5 m grid holds its energy to 2e-4 over 20 s at the default tolerance,
    1e-5 at a quarter of it. The substeps follow the grid's curvature (`stiffness`).

    Parameters
    ----------
    potential : sequence of rows of float
        ``phi`` at the grid's nodes in V, shape (rows, columns), at least 2 x 2; row 0 at the
        bottom, column 0 at the left (``potential[j][i]`` at ``(x_i, y_j)``).
    region : pair of (x, y), optional
        The lower-left and upper-right corners (m) of the grid, its first and last nodes (by
        default the vessel's bounding box).

    Examples
    --------
    >>> lens = FieldMap.sample(lambda x, y: 0.1 * (x**2 - y**2), ((-10, -10), (10, 10)), (41, 41))
    """

    name: ClassVar[str] = "field_map"
    #: The field differs from place to place (`collidium.forces.base.PositionForce.fall`).
    fall: ClassVar[None] = None

    potential: tuple[tuple[float, ...], ...]
    region: tuple[tuple[float, float], tuple[float, float]] | None = None
    _grid: FloatArray = field(init=False, repr=False, compare=False)
    _bends: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_grid", _grid(self.potential))
        object.__setattr__(self, "_bends", _bends(self._grid))
        object.__setattr__(self, "potential", tuple(tuple(row) for row in self._grid.tolist()))
        if self.region is not None:
            object.__setattr__(self, "region", check_rectangle(self.name, "region", self.region))

    @classmethod
    def sample(
        cls,
        function: Callable[[FloatArray, FloatArray], Any],
        region: tuple[tuple[float, float], tuple[float, float]],
        shape: tuple[int, int],
    ) -> FieldMap:
        """The map of ``function(x, y) -> phi`` (V; NumPy arrays of m in, broadcasting) on a
        grid of ``shape = (rows, columns)`` nodes spanning ``region``."""
        (left, bottom), (right, top) = check_rectangle(cls.name, "region", region)
        rows, columns = shape
        x, y = np.meshgrid(np.linspace(left, right, columns), np.linspace(bottom, top, rows))
        values = np.broadcast_to(np.asarray(function(x, y), dtype=float), x.shape)
        return cls(tuple(map(tuple, values.tolist())), ((left, bottom), (right, top)))

    def check(self, particles: Particles, vessel: Vessel) -> None:
        """Any vessel will do."""

    def compute(
        self,
        particles: Particles,
        vessel: Vessel,
        force: FloatArray,
        energy: FloatArray,
        virial: FloatArray,
        work: dict[str, np.ndarray],
        energies: bool,
    ) -> None:
        """``-q grad phi``, ``q phi`` and no virial (`collidium.forces.base.PositionForce`)."""
        phi, slope_x, slope_y = self._interpolate(particles.position, vessel)
        charge = particles.charge
        force[:, 0] = -charge * slope_x
        force[:, 1] = -charge * slope_y
        if not energies:
            return
        energy[...] = charge * phi
        virial[...] = 0.0

    def stiffness(self, particles: Particles, vessel: Vessel, acceleration: FloatArray) -> float:
        """``S`` (J^2/s^4) from each charge's speed over the grid's sharpest bend ``kappa``
        (V/m^2, its largest second difference) and its acceleration:
        ``(|q| kappa v^2 + m |a|^2)^2`` at most."""
        dx, dy = self._spacing(vessel)
        bend = float(np.max(self._bends / np.array([dx * dx, dy * dy, dx * dy])))
        v, a = particles.velocity, acceleration
        error = np.abs(particles.charge) * bend * np.einsum("ij,ij->i", v, v)
        error += particles.mass * np.einsum("ij,ij->i", a, a)
        return float(np.max(error * error, initial=0.0))

    def to_dict(self) -> dict[str, object]:
        """Parameters as in a scenario file."""
        region = {} if self.region is None else {"region": [list(c) for c in self.region]}
        return {"type": self.name, "potential": self._grid.tolist()} | region

    def _corners(self, vessel: Vessel) -> tuple[FloatArray, FloatArray]:
        if self.region is None:
            low, high = vessel.bounds
            return np.asarray(low, dtype=float), np.asarray(high, dtype=float)
        return np.asarray(self.region[0]), np.asarray(self.region[1])

    def _spacing(self, vessel: Vessel) -> FloatArray:
        """Node spacing (x, y) in m."""
        low, high = self._corners(vessel)
        rows, columns = self._grid.shape
        return (high - low) / np.array([columns - 1, rows - 1])

    def _interpolate(
        self, position: FloatArray, vessel: Vessel
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``phi`` (V) and its slopes along x and y (V/m) at ``position`` (N, 2)."""
        grid = self._grid
        rows, columns = grid.shape
        low, _ = self._corners(vessel)
        spacing = self._spacing(vessel)
        # Grid coordinates, held at the edges beyond them (where the slope across is 0).
        u = (position[:, 0] - low[0]) / spacing[0]
        w = (position[:, 1] - low[1]) / spacing[1]
        inside_u, inside_w = (u >= 0) & (u <= columns - 1), (w >= 0) & (w <= rows - 1)
        u, w = np.clip(u, 0, columns - 1), np.clip(w, 0, rows - 1)
        i = np.minimum(u.astype(np.intp), columns - 2)
        j = np.minimum(w.astype(np.intp), rows - 2)
        fu, fw = u - i, w - j
        p00, p10 = grid[j, i], grid[j, i + 1]
        p01, p11 = grid[j + 1, i], grid[j + 1, i + 1]
        bottom, top = p00 + fu * (p10 - p00), p01 + fu * (p11 - p01)
        phi = bottom + fw * (top - bottom)
        slope_x = np.where(inside_u, (1 - fw) * (p10 - p00) + fw * (p11 - p01), 0.0) / spacing[0]
        slope_y = np.where(inside_w, top - bottom, 0.0) / spacing[1]
        return phi, slope_x, slope_y


def _bends(grid: FloatArray) -> FloatArray:
    """The grid's largest second differences along x, along y and across, V (made once: the
    substeps ask for them at every boundary)."""
    return np.array([
        np.abs(np.diff(grid, 2, axis=1)).max(initial=0.0),
        np.abs(np.diff(grid, 2, axis=0)).max(initial=0.0),
        np.abs(np.diff(np.diff(grid, axis=0), axis=1)).max(),
    ])  # fmt: skip


def _grid(potential: Any) -> FloatArray:
    """The potential as a (rows, columns) array of floats, refused unless a finite grid of at
    least 2 x 2 nodes."""
    where = f"forces.{FieldMap.name}.potential"
    try:
        grid = np.array(potential, dtype=float)
    except (TypeError, ValueError):
        raise InputError(where, "must be rows of numbers, all of the same length") from None
    if grid.ndim != 2 or grid.shape[0] < 2 or grid.shape[1] < 2:
        raise InputError(where, f"must be a grid of at least 2 x 2 values, got shape {grid.shape}")
    if not np.isfinite(grid).all():
        j, i = np.argwhere(~np.isfinite(grid))[0]
        raise InputError(f"{where}.{j}.{i}", f"must be finite, got {grid[j, i]!r}")
    return grid
