"""Elastic collision of two disks (seed eq. 7), for any masses."""

from __future__ import annotations

import numba


@numba.njit(cache=True, inline="always")
def elastic_response(
    m1: float,
    m2: float,
    nx: float,
    ny: float,
    v1x: float,
    v1y: float,
    v2x: float,
    v2y: float,
) -> tuple[float, float, float, float]:
    """Post-collision velocities of two disks in contact.

    Parameters
    ----------
    m1, m2 : float
        Masses in kg.
    nx, ny : float
        Line of centres ``x1 - x2`` in m (need not be normalised).
    v1x, v1y, v2x, v2y : float
        Velocities before the collision in m/s.

    Returns
    -------
    tuple of float
        ``(v1x', v1y', v2x', v2y')``: momentum and kinetic energy are conserved; only the component
        along the line of centres changes.
    """
    n2 = nx * nx + ny * ny
    along = ((v1x - v2x) * nx + (v1y - v2y) * ny) / n2
    total = m1 + m2
    f1 = 2.0 * m2 / total * along
    f2 = 2.0 * m1 / total * along
    return v1x - f1 * nx, v1y - f1 * ny, v2x + f2 * nx, v2y + f2 * ny
