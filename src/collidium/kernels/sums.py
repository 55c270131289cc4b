"""Sums over the particles in particle order, compiled: the same bits in every path that sums.

The energies, momentum and total speed a run reports (`collidium.simulation.Simulation`) and
those the adaptive integrator's compiled intervals record at each step
(`collidium.kernels.substeps.smooth_intervals`) are summed by these loops, one value after the
other from 0: without fast-math flags LLVM keeps that order, so a run flown many steps in one
call reports them bit for bit as one stepped by Python would.
"""

from __future__ import annotations

import math

import numpy as np

from collidium.kernels.compilation import uncounted


@uncounted()
def kinetic_energy(mass: np.ndarray, velocity: np.ndarray) -> float:
    """``sum m v^2 / 2`` in J of masses (N,) in kg and velocities (N, 2) in m/s."""
    total = 0.0
    for i in range(mass.shape[0]):
        total += mass[i] * (velocity[i, 0] * velocity[i, 0] + velocity[i, 1] * velocity[i, 1])
    return 0.5 * total


@uncounted()
def momentum(mass: np.ndarray, velocity: np.ndarray) -> tuple[float, float]:
    """``sum m v``, (x, y) in kg m/s, of masses (N,) in kg and velocities (N, 2) in m/s."""
    px = 0.0
    py = 0.0
    for i in range(mass.shape[0]):
        px += mass[i] * velocity[i, 0]
        py += mass[i] * velocity[i, 1]
    return px, py


@uncounted()
def total_speed(velocity: np.ndarray) -> float:
    """``sum |v|`` in m/s of velocities (N, 2) in m/s (each ``sqrt(vx^2 + vy^2)``: ``hypot``
    guards against overflow past 1e154 m/s at ten times the cost)."""
    total = 0.0
    for i in range(velocity.shape[0]):
        total += math.sqrt(velocity[i, 0] * velocity[i, 0] + velocity[i, 1] * velocity[i, 1])
    return total


@uncounted()
def ordered_sum(values: np.ndarray) -> float:
    """The sum of ``values`` (N,) in index order, from 0."""
    total = 0.0
    for i in range(values.shape[0]):
        total += values[i]
    return total
