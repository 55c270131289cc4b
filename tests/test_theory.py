"""Reference results: 2D Maxwell-Boltzmann law, hard-disk equation of state."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from collidium.errors import InputError
from collidium.theory import MaxwellBoltzmann2D, hard_disk_compressibility, ideal_gas_pressure


@pytest.mark.parametrize("masses", [[1.0], [1.0, 1.0, 4.0], [0.1, 100.0]])
def test_maxwell_boltzmann_is_a_normalised_density_with_mean_kinetic_energy_kT(masses):
    kT = 2.5
    law = MaxwellBoltzmann2D(kT, masses)
    assert integrate.quad(law.pdf, 0, np.inf, limit=200)[0] == pytest.approx(1.0, abs=1e-9)
    assert law.cdf(np.inf) == pytest.approx(1.0, abs=1e-15)
    # Each species carries kT of kinetic energy in 2D: <m v^2 / 2> = kT.
    for m in law.masses:
        assert 0.5 * m * MaxwellBoltzmann2D(kT, m).moment(2) == pytest.approx(kT, rel=1e-12)


def test_single_mass_law_is_the_2d_formula():
    kT, m = 3.0, 2.0
    v = np.linspace(0.0, 8.0, 50)
    expected = (m * v / kT) * np.exp(-m * v**2 / (2 * kT))
    np.testing.assert_allclose(MaxwellBoltzmann2D(kT, m).pdf(v), expected, rtol=1e-12)


def test_mixture_weights_count_particles_of_each_mass():
    law = MaxwellBoltzmann2D(1.0, [1.0, 1.0, 1.0, 9.0])
    np.testing.assert_allclose(law.weights, [0.75, 0.25])
    light, heavy = MaxwellBoltzmann2D(1.0, 1.0), MaxwellBoltzmann2D(1.0, 9.0)
    v = np.array([0.2, 1.0, 3.0])
    np.testing.assert_allclose(law.pdf(v), 0.75 * light.pdf(v) + 0.25 * heavy.pdf(v), rtol=1e-14)


def test_bad_temperature_is_refused():
    with pytest.raises(InputError, match="temperature"):
        MaxwellBoltzmann2D(0.0, 1.0)


def test_henderson_equation_of_state_against_the_virial_series():
    # Reduced virial coefficients of hard disks (Clisby and McCoy 2006), Z = 1 + sum b_k eta^k.
    b = [2.0, 3.12801775, 4.25785446, 5.33689664, 6.36296, 7.35186, 8.3077, 9.2271, 10.1]
    for eta in (0.01, 0.1, 0.2, 0.3):
        series = 1 + sum(bk * eta ** (k + 1) for k, bk in enumerate(b))
        assert hard_disk_compressibility(eta) == pytest.approx(series, rel=1e-3)
    assert hard_disk_compressibility(0.0) == 1.0
    with pytest.raises(InputError, match="packing"):
        hard_disk_compressibility(0.8)


def test_ideal_gas_pressure():
    assert ideal_gas_pressure(200, 2.0, 400.0) == 1.0
