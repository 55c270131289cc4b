"""Wall responses in a vessel: thermal walls bring a gas to their temperature and carry heat from
hot to cold with every joule booked; inelastic walls cool it by what they book; bad walls are
refused with the field named; runs with thermal walls resume bitwise."""

from __future__ import annotations

import math

import numpy as np
import pytest

import collidium as cd
from collidium import InputError
from collidium.observers import EnergyDrift
from collidium.scenario import Scenario
from collidium.vessels import Inelastic, Thermal


def gas_between(walls: dict, n: int = 100, mode: str = "exact", shape: dict | None = None):
    vessel = (shape or {}) | {"walls": walls}
    return Scenario.from_dict(
        {
            "seed": 4,
            "vessel": vessel,
            "run": {"collisions": mode, "dt": 0.05},
            "particles": [{"kind": "random", "n": n, "speed": 2.0}],
        }
    ).build()


def kinetic(sim: cd.Simulation) -> float:
    return sim.energy().kinetic


def mean_and_error(samples: list[float], blocks: int = 20) -> tuple[float, float]:
    means = [np.mean(b) for b in np.array_split(np.asarray(samples), blocks)]
    return float(np.mean(means)), float(np.std(means, ddof=1) / math.sqrt(blocks))


THERMAL = {"response": "thermal", "temperature": 3.0}


@pytest.mark.parametrize(
    ("mode", "shape"),
    [("off", None), ("exact", None), ("exact", {"shape": "circle", "radius": 8.0})],
)
def test_thermal_walls_at_one_temperature_bring_the_gas_to_it(mode, shape):
    names = ("rim",) if shape else ("left", "right", "bottom", "top")
    sim = gas_between(dict.fromkeys(names, THERMAL), mode=mode, shape=shape)
    sim.run(time=40.0)  # relax: about 10 wall hits per disk
    samples = []
    for _ in range(400):
        sim.run(steps=2)
        samples.append(sim.temperature())
    kT, error = mean_and_error(samples)
    assert abs(kT - 3.0) < 3 * error, (kT, error)
    assert sim.escaped() == 0


@pytest.mark.parametrize("mode", ["exact", "step", "off"])
def test_heat_flows_from_the_hot_wall_to_the_cold_one_and_every_joule_is_booked(mode):
    hot, cold = (
        {"response": "thermal", "temperature": 6.0},
        {"response": "thermal", "temperature": 1.0},
    )
    sim = gas_between({"left": hot, "right": cold}, mode=mode)
    drift = EnergyDrift()
    sim.observers.append(drift)
    start = kinetic(sim)
    sim.run(time=30.0)
    assert drift.max_rel_drift < 1e-12  # what is conserved: the energy less the walls' heat
    heat = sim.wall_heat()
    # Without forces the kinetic energy changes only at the thermal walls: to round-off.
    assert kinetic(sim) - start == pytest.approx(sum(heat.values()), rel=1e-9, abs=1e-9)
    before = dict(heat)
    sim.run(time=60.0)
    flux = {name: sim.wall_heat()[name] - before[name] for name in ("left", "right")}
    assert flux["left"] > 0 > flux["right"]  # in at the hot wall, out at the cold one
    # In the steady state what comes in goes out, up to the gas's fluctuating energy.
    assert abs(flux["left"] + flux["right"]) < 0.25 * flux["left"]
    assert heat["bottom"] == heat["top"] == 0.0 and sim.escaped() == 0


@pytest.mark.parametrize("mode", ["exact", "off"])
def test_an_inelastic_wall_cools_the_gas_by_what_it_books(mode):
    sim = gas_between({"bottom": {"response": "inelastic", "restitution": 0.5}}, mode=mode)
    start = kinetic(sim)
    along = 0.5 * np.sum(sim.particles.mass * sim.particles.velocity[:, 0] ** 2)
    sim.run(time=20.0)
    lost = sim.wall_heat()["bottom"]
    assert lost < -0.2 * start  # many hits, each losing 3/4 of the normal energy
    assert kinetic(sim) - start == pytest.approx(lost, rel=1e-9)
    if mode == "off":  # the bottom wall takes only vertical motion
        x_energy = 0.5 * np.sum(sim.particles.mass * sim.particles.velocity[:, 0] ** 2)
        assert x_energy == pytest.approx(along, rel=1e-12)


def test_thermal_walls_resume_bitwise_from_a_checkpoint(tmp_path):
    sim = gas_between({"left": THERMAL, "top": THERMAL})
    sim.run(time=5.0).save(tmp_path / "t.ckpt")
    whole = sim.run(time=5.0)
    again = cd.restore(tmp_path / "t.ckpt").run(time=5.0)
    assert again.particles.velocity.tobytes() == whole.particles.velocity.tobytes()
    assert again.wall_heat() == whole.wall_heat()
    assert again.container.to_dict() == whole.container.to_dict()


@pytest.mark.parametrize(
    ("walls", "field", "reason"),
    [
        ({"left": {"response": "inelastic", "restitution": 0.0}}, "vessel.walls.left.restitution",
         "must be > 0"),
        ({"left": {"response": "inelastic", "restitution": 1.5}}, "vessel.walls.left.restitution",
         "must be <= 1"),
        ({"top": {"response": "thermal", "temperature": -1.0}}, "vessel.walls.top.temperature",
         "must be > 0"),
        ({"top": {"response": "sticky"}}, "vessel.walls.top.response", "unknown value 'sticky'"),
        ({"roof": {"response": "specular"}}, "vessel.walls.roof", "no such wall"),
    ],
)  # fmt: skip
def test_bad_walls_name_the_field(walls, field, reason):
    with pytest.raises(InputError) as info:
        gas_between(walls)
    assert info.value.field == field and reason in info.value.reason


def test_bad_walls_in_python_name_the_field():
    with pytest.raises(InputError, match="restitution: must be in"):
        Inelastic(0.0)
    with pytest.raises(InputError, match="temperature: must be a finite number > 0"):
        Thermal(math.nan)
    with pytest.raises(InputError, match=r"vessel\.walls\.left: no such wall; the walls are: none"):
        cd.Box(10, 10, "periodic", walls={"left": Thermal(1.0)})


def test_walls_survive_a_scenario_file(tmp_path):
    sim = gas_between({"left": THERMAL, "bottom": {"response": "inelastic", "restitution": 0.8}})
    scenario = Scenario.of_state(sim)
    path = tmp_path / "walls.toml"
    path.write_text(scenario.to_toml())
    assert "[vessel.walls.left]" in path.read_text()
    again = Scenario.from_toml(path).build()
    assert again.container.to_dict() == sim.container.to_dict()
    assert (
        again.run(time=3.0).particles.velocity.tobytes()
        == sim.run(time=3.0).particles.velocity.tobytes()
    )
