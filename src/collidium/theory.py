"""Results from theory that measurements are compared with: the 2D Maxwell-Boltzmann speed
distribution, the ideal gas and the hard-disk equation of state, Haff's cooling law, effusion,
the barometric law and the range of a projectile. Boltzmann's constant is 1 (temperatures kT in
J)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from collidium.errors import InputError
from collidium.state import FloatArray


class MaxwellBoltzmann2D:
    """Speed distribution of a 2D gas in equilibrium at temperature kT.

    For one mass it is a Rayleigh distribution of scale ``sqrt(kT / m)``,
    ``f(v) = (m v / kT) exp(-m v^2 / (2 kT))``; for several masses the mixture of those, weighted
    by the number of particles of each mass.

    Parameters
    ----------
    kT : float
        Temperature in J (> 0).
    mass : array_like
        Mass of each particle in kg (shape (N,)), or a single mass.
    """

    def __init__(self, kT: float, mass: ArrayLike) -> None:
        if not np.isfinite(kT) or kT <= 0:
            raise InputError("temperature", f"must be a finite number > 0, got {kT!r}")
        each: FloatArray = np.atleast_1d(np.asarray(mass, dtype=float))
        if each.size and each.min() == each.max():  # one mass: no sort of N masses
            masses, counts = each[:1], np.array([each.size])
        else:
            masses, counts = np.unique(each, return_counts=True)
        self.kT = float(kT)
        self.masses = masses
        self.weights = counts / counts.sum()

    @property
    def scales(self) -> FloatArray:
        """The Rayleigh scale ``sqrt(kT / m)`` of each mass, m/s. The laws are scipy's
        ``rayleigh`` at these scales, called unfrozen: freezing one builds a distribution
        object, a hundred times the cost of a density (the viewer draws one a readout)."""
        return np.sqrt(self.kT / self.masses)

    def pdf(self, speed: ArrayLike) -> FloatArray:
        """Probability density at ``speed`` (m/s), in s/m."""
        return self._mixture("pdf", speed)

    def cdf(self, speed: ArrayLike) -> FloatArray:
        """Probability of a speed below ``speed`` (m/s)."""
        return self._mixture("cdf", speed)

    def mean(self) -> float:
        """Mean speed in m/s."""
        return float(self._mixture("mean"))

    def moment(self, order: int) -> float:
        """The mean of ``speed**order``, (m/s)^order."""
        return float(self._mixture("moment", order))

    def _mixture(self, method: str, *args: ArrayLike) -> FloatArray:
        """The weighted sum of the components' ``method``."""
        from scipy import stats  # imported on first use: it is slow to load

        law = getattr(stats.rayleigh, method)
        return np.asarray(
            sum(w * law(*args, scale=s) for w, s in zip(self.weights, self.scales, strict=True))
        )

    def bin_probabilities(self, edges: ArrayLike) -> FloatArray:
        """Probability of each bin between consecutive ``edges`` (m/s)."""
        return np.diff(self.cdf(edges))


def ideal_gas_pressure(n: int, kT: float, area: float) -> float:
    """Pressure ``N kT / A`` of an ideal 2D gas in N/m, for N particles in area A (m^2)."""
    return n * kT / area


def hard_disk_compressibility(packing: float) -> float:
    """Compressibility factor ``Z = P A / (N kT)`` of the hard-disk fluid (Henderson 1975).

    ``Z = (1 + eta^2 / 8) / (1 - eta)^2`` at packing fraction eta, in the fluid (eta below about
    0.69, where the fluid branch ends). It differs from the virial series by 0.03% at eta = 0.3
    and about 0.2% at eta = 0.4.
    """
    if not 0 <= packing < 0.69:
        raise InputError("packing", f"the fluid branch needs 0 <= eta < 0.69, got {packing}")
    return (1 + packing**2 / 8) / (1 - packing) ** 2


#: Reduced virial coefficients ``b_2 ... b_10`` of hard disks (Clisby and McCoy 2006), in
#: ``Z = 1 + sum_k b_(k+2) eta^(k+1)``.
HARD_DISK_VIRIAL_COEFFICIENTS = (
    2.0, 3.12801775, 4.25785446, 5.33689664, 6.36296, 7.35186, 8.3077, 9.2271, 10.1,
)  # fmt: skip


def hard_disk_virial_series(packing: float) -> float:
    """``Z`` of the hard-disk fluid from its virial series to the tenth coefficient: a check of
    `hard_disk_compressibility` (their distance bounds Henderson's error at low packing)."""
    return 1.0 + sum(b * packing ** (k + 1) for k, b in enumerate(HARD_DISK_VIRIAL_COEFFICIENTS))


def contact_value(packing: float) -> float:
    """Pair correlation at contact ``chi`` of the hard-disk fluid, from Henderson's equation of
    state (``Z = 1 + 2 eta chi``): ``chi = (1 - 7 eta / 16) / (1 - eta)^2``."""
    hard_disk_compressibility(packing)  # the same fluid range
    return (1 - 7 * packing / 16) / (1 - packing) ** 2


def haff_time(density: float, diameter: float, kT: float, mass: float, restitution: float) -> float:
    """Haff's cooling time ``tau`` (s) of a homogeneous granular gas of disks in 2D.

    Each collision takes ``(1 - e^2) kT`` on average (the normal approach speed squared,
    averaged over collisions, is ``4 kT / m``) and a disk collides ``2 n sigma chi
    sqrt(pi kT / m)`` times per second (Enskog), so ``dT/dt = -(1 - e^2) n sigma chi
    sqrt(pi / m) T^(3/2)`` and ``T(t) = T0 / (1 + t / tau)^2`` with
    ``tau = 2 / ((1 - e^2) n sigma chi sqrt(pi T0 / m))``.

    Parameters
    ----------
    density : float
        Number of disks per unit area, 1/m^2.
    diameter : float
        Disk diameter sigma, m.
    kT : float
        Initial temperature T0 (kinetic energy per disk), J.
    mass : float
        Disk mass, kg.
    restitution : float
        Normal restitution coefficient e, in (0, 1).
    """
    packing = density * math.pi * diameter**2 / 4
    rate = (1 - restitution**2) * density * diameter * contact_value(packing)
    return 2.0 / (rate * math.sqrt(math.pi * kT / mass))


def haff_temperature(time: ArrayLike, kT: float, tau: float) -> FloatArray:
    """Haff's law ``T(t) = T0 / (1 + t / tau)^2`` (J) of a cooling granular gas."""
    return np.asarray(kT / (1.0 + np.asarray(time, dtype=float) / tau) ** 2)


def effusion_rate(normal_speed: float, width: float, area: float) -> float:
    """Crossings per disk per second, both ways, through a hole between two chambers of equal
    area, narrow against the mean free path (effusion, 2D).

    Disks of number density ``n`` on one side cross at ``n <v_n+> w`` per second, ``<v_n+>`` the
    mean of the positive part of the velocity along the hole's normal, which is half the mean of
    ``|v_n|`` for a symmetric distribution. Both ways with ``N`` disks in two chambers of area
    ``A`` each, that is ``(N / A) <|v_n|> w / 2``, however the disks are shared: per disk
    ``<|v_n|> w / (2 A)``. In equilibrium ``<|v_n|> = sqrt(2 kT / (pi m))``: the rate goes as
    ``1 / sqrt(m)`` (Graham's law).

    Parameters
    ----------
    normal_speed : float
        Mean ``|v_n|`` over the disks, m/s.
    width : float
        Width of the opening open to centres, m (the hole less a diameter).
    area : float
        Area of one chamber open to centres, m^2.
    """
    return normal_speed * width / (2.0 * area)


def barometric_density(height: ArrayLike, mass: float, g: float, kT: float) -> FloatArray:
    """The barometric law: the density of a dilute gas at ``height`` (m) relative to its density
    at height 0, ``exp(-m g y / kT)``, under gravity ``g`` (m/s^2) at temperature kT (J)."""
    return np.exp(-mass * g * np.asarray(height, dtype=float) / kT)


def projectile_range(speed: float, drop: float, acceleration: float) -> float:
    """How far (m) a body launched level at ``speed`` (m/s) travels while it falls ``drop`` m
    under a constant ``acceleration`` (m/s^2): ``speed sqrt(2 drop / acceleration)``."""
    return speed * math.sqrt(2.0 * drop / acceleration)


def cyclotron_radius(mass: float, speed: float, charge: float, field: float) -> float:
    """Radius (m) of the circle a charge (C) of ``mass`` (kg) moving at ``speed`` (m/s) runs in a
    magnetic ``field`` (T) normal to its velocity: ``m v / (|q| B)``."""
    return mass * speed / abs(charge * field)


def terminal_velocity(mass: float, g: float, gamma: float) -> float:
    """Speed (m/s) at which linear drag ``gamma`` (kg/s) balances the weight ``m g``:
    ``m g / gamma``."""
    return mass * g / gamma
