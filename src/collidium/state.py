"""Particle state: a struct of arrays, validated once on entry."""

from __future__ import annotations

from typing import Any, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from collidium.errors import InputError

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

#: The speed of light, m/s: collidium's mechanics is Newtonian, for particles slower than this.
SPEED_OF_LIGHT = 299_792_458.0


def _per_particle(name: str, value: ArrayLike, n: int) -> FloatArray:
    """A length-N sequence as a fresh (N,) float64 array; a scalar as the value all N particles
    share, stored once (a read-only (N,) view of it: 8 bytes whatever N). Checked finite, and
    mass > 0, radius >= 0."""
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"not a number or list of numbers ({exc})") from None
    if array.ndim > 0 and array.shape != (n,):
        raise InputError(name, f"expected a scalar or {n} values, got shape {array.shape}")
    values = array.reshape(-1)  # a shared value is checked once, as particle 0's
    _check_finite(name, values)
    wrong = {"mass": values <= 0, "radius": values < 0}.get(name)
    if wrong is not None and wrong.any():
        i = int(np.flatnonzero(wrong)[0])
        sign = ">" if name == "mass" else ">="
        raise InputError(name, f"must be {sign} 0, particle {i} has {float(values[i])!r}")
    return np.broadcast_to(array, (n,)) if array.ndim == 0 else array


def _check_slower_than_light(velocity: FloatArray) -> None:
    """Refuse a velocity (N, 2) at or past the speed of light, naming the first such particle."""
    with np.errstate(over="ignore"):  # a square past float64 is past light too
        speed2 = np.einsum("ij,ij->i", velocity, velocity)
    fast = np.flatnonzero(speed2 >= SPEED_OF_LIGHT**2)
    if fast.size:
        i = int(fast[0])
        raise InputError(
            "velocity",
            f"particle {i} moves at {float(np.sqrt(speed2[i])):.3g} m/s, not below the speed "
            f"of light ({SPEED_OF_LIGHT:.0f} m/s): the mechanics is Newtonian",
        )


def _check_finite(name: str, values: FloatArray) -> None:
    """Refuse NaN or infinity in (N,) or (N, 2) ``values``, naming the first particle."""
    finite = np.isfinite(values)
    bad = np.flatnonzero(~(finite.all(axis=1) if values.ndim == 2 else finite))
    if bad.size:
        raise InputError(name, f"not finite (NaN or infinity) for particle {int(bad[0])}")


class _PerParticle:
    """A float property of each particle, (N,): validated on assignment (`_per_particle`)."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, particles: None, owner: type) -> _PerParticle: ...
    @overload
    def __get__(self, particles: Particles, owner: type | None = None) -> FloatArray: ...
    def __get__(self, particles: Particles | None, owner: type | None = None) -> Any:
        return self if particles is None else particles.__dict__[self.name]

    def __set__(self, particles: Particles, value: ArrayLike) -> None:
        particles.__dict__[self.name] = _per_particle(self.name, value, particles.n)


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

        Each of ``mass``, ``radius`` and ``charge`` is an (N,) array, checked again whenever it is
        assigned. Given as a scalar, it is the value all particles share, stored once (8 bytes
        instead of 8 N: a million disks need 24 MB less) and read-only: assign a new scalar
        (``p.radius = 0.4``) or an array (``p.mass = p.mass.copy()``, then edit it in place).
    image : array_like of int, shape (N, 2), optional
        Periodic image counts: unwrapped position = position + image * (width, height).

    Raises
    ------
    InputError
        On a wrong shape, NaN or infinity, a speed not below light's, mass <= 0 or radius < 0.
        Overlaps and the vessel are checked by `Simulation`, which knows the container.
    """

    position: FloatArray
    velocity: FloatArray
    mass = _PerParticle()
    radius = _PerParticle()
    charge = _PerParticle()
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
        _check_finite("position", self.position)
        _check_finite("velocity", self.velocity)
        _check_slower_than_light(self.velocity)
        self.mass = mass
        self.radius = radius
        self.charge = charge
        self.image = np.zeros((n, 2), dtype=np.int64)
        if image is not None:
            self.image[...] = np.asarray(image, dtype=np.int64).reshape(n, 2)

    @property
    def n(self) -> int:
        """Number of particles N."""
        return int(self.position.shape[0])

    def __len__(self) -> int:
        return self.n

    def copy(self) -> Particles:
        """A deep copy (arrays are copied; shared values stay shared)."""
        return Particles(*self.__reduce__()[1])

    def joined(self, other: Particles) -> Particles:
        """These particles followed by ``other``'s (a value both share stays shared)."""
        properties: list[float | FloatArray] = []
        for name in PROPERTIES:
            mine, theirs = as_given(getattr(self, name)), as_given(getattr(other, name))
            same = isinstance(mine, float) and isinstance(theirs, float) and mine == theirs
            properties.append(
                mine if same else np.concatenate([getattr(self, name), getattr(other, name)])
            )
        mass, radius, charge = properties
        return Particles(
            np.concatenate([self.position, other.position]),
            np.concatenate([self.velocity, other.velocity]),
            mass, radius, charge, np.concatenate([self.image, other.image]),
        )  # fmt: skip

    def without(self, indices: ArrayLike) -> Particles:
        """These particles less those at ``indices`` (the rest keep their order)."""
        keep = np.ones(self.n, dtype=bool)
        keep[np.asarray(indices, dtype=np.int64)] = False
        given = (as_given(getattr(self, name)) for name in PROPERTIES)
        mass, radius, charge = (
            value if isinstance(value, float) else value[keep] for value in given
        )
        return Particles(
            self.position[keep], self.velocity[keep], mass, radius, charge, self.image[keep]
        )

    def __deepcopy__(self, memo: dict[int, object]) -> Particles:
        return self.copy()

    def __reduce__(self) -> tuple[type[Particles], tuple[Any, ...]]:
        # Pickled as given, so that a shared value is not spread over N entries.
        given = (as_given(getattr(self, name)) for name in PROPERTIES)
        return Particles, (self.position, self.velocity, *given, self.image)


#: The per-particle properties that a scalar gives to all particles (`Particles`).
PROPERTIES = ("mass", "radius", "charge")


def writable(values: FloatArray) -> FloatArray:
    """``values`` (N,) as a contiguous writable array, copied if it is not one: a value all
    particles share is a read-only view of stride 0 (`collidium.state.Particles`), another type
    to numba, which would compile a kernel a second time for it: a copy costs O(N), less than
    any kernel that takes it."""
    if values.flags.c_contiguous and values.flags.writeable:
        return values
    return np.array(values)


def as_given(values: FloatArray) -> float | FloatArray:
    """A property of `Particles` as it was given: the shared value if it is stored once, else the
    per-particle array (to copy or save it without spreading a shared value over N entries)."""
    shared = values.size > 0 and values.strides == (0,)
    return float(values[0]) if shared else values


def uniform_or_each(values: FloatArray) -> float | FloatArray:
    """One value when every particle has the same, else the per-particle array (for compact
    files and messages)."""
    return float(values[0]) if values.size and (values == values[0]).all() else values
