"""Particle state: a struct of arrays, validated once on entry."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from collidium.errors import InputError

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def _per_particle(name: str, value: ArrayLike, n: int) -> FloatArray:
    """Broadcast a scalar or length-N sequence to a fresh (N,) float64 array."""
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"not a number or list of numbers ({exc})") from None
    if array.ndim == 0:
        return np.full(n, float(array))
    if array.shape != (n,):
        raise InputError(name, f"expected a scalar or {n} values, got shape {array.shape}")
    return array


def _vectors(name: str, value: ArrayLike) -> FloatArray:
    """A fresh (N,2) float64 array of 2D vectors."""
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"not an array of numbers ({exc})") from None
    if array.ndim == 1 and array.size == 0:
        array = array.reshape(0, 2)
    if array.ndim != 2 or array.shape[1] != 2:
        raise InputError(name, f"expected shape (N, 2), got {array.shape}")
    return array


class Particles:
    """Disks in the plane, stored as a struct of arrays (SI-like units of the seed report).

    Parameters
    ----------
    position : array_like, shape (N, 2)
        Centres in m.
    velocity : array_like, shape (N, 2), optional
        Velocities in m/s; zero when omitted.
    mass : float or array_like, shape (N,)
        Masses in kg, > 0.
    radius : float or array_like, shape (N,)
        Radii in m, >= 0. A radius-0 particle takes no part in pair collisions.
    charge : float or array_like, shape (N,)
        Charges in C.
    image : array_like of int, shape (N, 2), optional
        Periodic image counts: unwrapped position = position + image * (width, height).

    Raises
    ------
    InputError
        On a wrong shape, NaN or infinity, mass <= 0 or radius < 0. Overlaps and the vessel are
        checked by `Simulation`, which knows the container.
    """

    position: FloatArray
    velocity: FloatArray
    mass: FloatArray
    radius: FloatArray
    charge: FloatArray
    image: IntArray

    def __init__(
        self,
        position: ArrayLike,
        velocity: ArrayLike | None = None,
        mass: ArrayLike = 1.0,
        radius: ArrayLike = 0.25,
        charge: ArrayLike = 0.0,
        image: ArrayLike | None = None,
    ) -> None:
        self.position = _vectors("position", position)
        n = self.position.shape[0]
        self.velocity = _vectors("velocity", np.zeros((n, 2)) if velocity is None else velocity)
        if self.velocity.shape != (n, 2):
            raise InputError("velocity", f"expected shape ({n}, 2), got {self.velocity.shape}")
        self.mass = _per_particle("mass", mass, n)
        self.radius = _per_particle("radius", radius, n)
        self.charge = _per_particle("charge", charge, n)
        self.image = np.zeros((n, 2), dtype=np.int64)
        if image is not None:
            self.image[...] = np.asarray(image, dtype=np.int64).reshape(n, 2)
        self._check_values()

    def _check_values(self) -> None:
        for name in ("position", "velocity", "mass", "radius", "charge"):
            values = getattr(self, name).reshape(self.n, -1 if self.n else 1)
            bad = np.flatnonzero(~np.isfinite(values).all(axis=1))
            if bad.size:
                raise InputError(name, f"not finite (NaN or infinity) for particle {int(bad[0])}")
        if (self.mass <= 0).any():
            i = int(np.flatnonzero(self.mass <= 0)[0])
            raise InputError("mass", f"must be > 0, particle {i} has {self.mass[i]!r}")
        if (self.radius < 0).any():
            i = int(np.flatnonzero(self.radius < 0)[0])
            raise InputError("radius", f"must be >= 0, particle {i} has {self.radius[i]!r}")

    @property
    def n(self) -> int:
        """Number of particles N."""
        return int(self.position.shape[0])

    def __len__(self) -> int:
        return self.n

    def copy(self) -> Particles:
        """A deep copy (arrays are copied)."""
        return Particles(
            position=self.position.copy(),
            velocity=self.velocity.copy(),
            mass=self.mass.copy(),
            radius=self.radius.copy(),
            charge=self.charge.copy(),
            image=self.image.copy(),
        )


def uniform_or_each(values: FloatArray) -> float | FloatArray:
    """One value when every particle has the same, else the per-particle array (for compact
    files and messages)."""
    return float(values[0]) if values.size and (values == values[0]).all() else values
