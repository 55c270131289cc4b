"""Traced paths and mean-square displacement (the seed's random-walk idea)."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure
from test_thermo import hard_disk_fluid

import collidium as cd
from collidium.errors import InputError
from collidium.observers import Every, Tracer


def test_free_flight_is_ballistic_across_periodic_boundaries():
    """Without collisions the unwrapped displacement is v t exactly, so MSD = <v^2> t^2 even after
    particles have crossed the box many times."""
    sim = cd.load("gas", collisions="off", **{"vessel.boundary": "periodic"})
    tracer = Tracer(trigger=Every(100))
    sim.observers.append(tracer)
    sim.run(time=10.0)
    speed2 = np.mean(np.sum(sim.particles.velocity**2, axis=1))
    np.testing.assert_allclose(tracer.msd(), speed2 * tracer.time**2, rtol=1e-9)
    assert np.abs(sim.particles.image).max() > 1  # they did wrap


def test_collisions_make_the_motion_diffusive():
    """In a periodic fluid the MSD grows linearly once many collisions have happened: equal
    increments over equal times, and far below the ballistic v^2 t^2."""
    sim = hard_disk_fluid(0.3, n_side=20)
    tracer = Tracer(trigger=Every(50))
    sim.observers.append(tracer)
    sim.run(time=200.0)
    msd, time = tracer.msd(), tracer.time - tracer.time[0]

    def slope(start, end):
        inside = (time >= start) & (time <= end)
        return np.polyfit(time[inside], msd[inside], 1)[0]

    # Two disjoint windows long after the mean free time (about 0.5 s): the same growth rate
    # within the spread of an average over 400 disks (a few %), unlike ballistic motion (where
    # the rate doubles between them).
    early, late = slope(50.0, 100.0), slope(150.0, 200.0)
    assert late == pytest.approx(early, rel=0.2)
    assert tracer.diffusion_coefficient() == pytest.approx(0.25 * slope(100.0, 200.0), rel=1e-9)
    assert msd[-1] < 0.01 * 2.0 * time[-1] ** 2  # <v^2> = 2 kT / m = 2


def test_chosen_particles_only():
    sim = cd.load("gas")
    tracer = Tracer([3, 7], trigger=Every(10))
    sim.observers.append(tracer)
    sim.run(time=1.0)
    assert tracer.path.shape == (11, 2, 2)
    np.testing.assert_array_equal(tracer.path[-1], sim.particles.position[[3, 7]])
    ax = tracer.plot(Figure().add_subplot())
    assert len(ax.get_lines()) == 2


def test_bad_index_is_refused():
    with pytest.raises(InputError, match="particles"):
        Tracer([0, 999]).compute(cd.load("head-on"))
