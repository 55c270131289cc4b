"""Energies summed in particle order, compiled: the same bits in every path that sums them.

The kinetic energy and the potential energy a run reports (`collidium.simulation.Simulation.energy`)
and those the adaptive integrator's compiled intervals record at each step
(`collidium.kernels.substeps.smooth_intervals`) are summed by these loops, one value after the
other from 0: without fast-math flags LLVM keeps that order, so a run flown many steps in one
call reports its energies bit for bit as one stepped by Python would.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def kinetic_energy(mass: np.ndarray, velocity: np.ndarray) -> float:
    """``sum m v^2 / 2`` in J of masses (N,) in kg and velocities (N, 2) in m/s, summed in
    particle order."""
    total = 0.0
    for i in range(mass.shape[0]):
        total += mass[i] * (velocity[i, 0] * velocity[i, 0] + velocity[i, 1] * velocity[i, 1])
    return 0.5 * total


@numba.njit(cache=True)
def ordered_sum(values: np.ndarray) -> float:
    """The sum of ``values`` (N,) in index order, from 0."""
    total = 0.0
    for i in range(values.shape[0]):
        total += values[i]
    return total
