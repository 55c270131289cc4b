"""Temperature profile: flat in equilibrium within its errors, sliced along either axis, bad
parameters refused."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from collidium import InputError, load
from collidium.observers import TemperatureProfile


@pytest.mark.slow
@pytest.mark.parametrize("axis", ["x", "y"])
def test_an_equilibrium_gas_has_a_flat_profile(axis):
    sim = load("gas", seed=5).run(time=20.0)  # relaxed from the uniform start
    profile = TemperatureProfile(bins=8, axis=axis, trigger=5)
    sim.observers.append(profile)
    sim.run(time=300.0)  # blocks of 15 s, longer than the slices' correlation time
    kT, error = profile.temperature, profile.temperature_error()
    np.testing.assert_allclose(profile.centres, np.linspace(-8.75, 8.75, 8))
    # Each slice scatters about the mean by its error: chi-square with 7 degrees of freedom.
    mean = np.average(kT, weights=1 / error**2)
    chi2 = float(np.sum(((kT - mean) / error) ** 2))
    assert stats.chi2.sf(chi2, 7) > 1e-3, (kT, error)
    assert mean == pytest.approx(sim.temperature(), rel=0.1)
    summary = profile.summary()
    assert summary["axis"] == axis and len(summary["temperature"]) == 8
    assert profile.plot() is not None


@pytest.mark.parametrize(("kwargs", "field"), [({"bins": 0}, "bins"), ({"axis": "z"}, "axis")])
def test_bad_parameters_name_the_field(kwargs, field):
    with pytest.raises(InputError) as info:
        TemperatureProfile(**kwargs)
    assert info.value.field == field
