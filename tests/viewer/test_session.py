"""The viewer's session: controls change the simulation as they say, readouts measure it."""

from __future__ import annotations

import numpy as np
import pytest

from collidium.errors import InputError, SimulationError
from collidium.observers.thermo import Thermo
from collidium.presets import PRESETS, preset
from collidium.scenario import Scenario
from collidium.theory import MaxwellBoltzmann2D
from collidium.viewer import moving_wall, protocol
from collidium.viewer import session as session_module
from collidium.viewer.session import WINDOW_SAMPLES, ViewerSession


@pytest.fixture
def gas() -> ViewerSession:
    return ViewerSession(preset("gas", n=100), preset="gas", overrides={"n": 100})


def test_the_first_advances_run_one_step_each_to_learn_its_cost_and_keep_the_rest(gas):
    """The first step loads the kernels (untimed), the second learns what a step costs."""
    gas.advance(0.1, budget=10.0)
    assert gas.sim.steps == 1 and gas._seconds_per_step is None
    gas.advance(0.0, budget=10.0)
    assert gas.sim.steps == 2 and gas._seconds_per_step > 0
    gas.advance(0.0, budget=10.0)  # the 8 steps still owed are run
    assert gas.sim.steps == 10


def test_advance_runs_speed_times_the_wall_time_in_whole_steps(gas):
    gas._seconds_per_step = 1e-6
    gas.set_speed(2.0)
    gas.advance(0.1, budget=10.0)
    assert gas.sim.steps == 20
    gas.advance(0.004, budget=10.0)  # 0.8 of a step is carried over...
    assert gas.sim.steps == 20
    gas.advance(0.001, budget=10.0)  # ...and taken once a whole step has accumulated
    assert gas.sim.steps == 21


def test_advance_owes_the_time_it_cannot_afford_up_to_a_limit_and_never_runs_while_paused(gas):
    gas._seconds_per_step = 1.0  # as if each step took a second
    gas.advance(0.2, budget=0.01)
    assert gas.sim.steps == 1  # one step, not the 20 asked for...
    gas._seconds_per_step = 1e-6
    gas.advance(0.0, budget=10.0)
    assert gas.sim.steps == 20  # ...the 19 owed follow once they fit
    gas._seconds_per_step = 1.0
    gas.advance(10.0, budget=0.01)  # a backlog past MAX_CATCH_UP is dropped
    gas._seconds_per_step = 1e-6
    gas.advance(0.0, budget=10.0)
    assert gas.sim.steps == 20 + round(session_module.MAX_CATCH_UP / gas.sim.dt)
    gas.playing = False
    gas.advance(0.2, budget=10.0)
    assert gas.sim.steps == 20 + round(session_module.MAX_CATCH_UP / gas.sim.dt)


def test_advance_runs_as_many_whole_steps_as_fit_its_budget(gas):
    gas._seconds_per_step = 0.6  # a step over half the budget: one fits
    gas.advance(0.2, budget=1.0)
    assert gas.sim.steps == 1
    gas._seconds_per_step = 0.9  # three fit (2.7 s), a fourth would overspend
    gas.advance(0.0, budget=3.0)
    assert gas.sim.steps == 4


def test_heat_multiplies_the_kinetic_energy_and_restarts_the_drift(gas):
    before = gas.sim.energy().kinetic
    gas.heat(1.25)
    assert gas.sim.energy().kinetic == pytest.approx(1.25 * before, rel=1e-13)
    assert gas.stats()["drift"] == 0.0
    gas.heat(0.8)
    assert gas.sim.energy().kinetic == pytest.approx(before, rel=1e-13)


def test_collisions_switch_off_and_back_to_the_scenario_mode(gas):
    gas.enable_collisions(False)
    assert gas.sim.collisions == "off"
    pairs = gas.sim.counters.pair_collisions
    gas.sim.run(time=2.0)
    assert gas.sim.counters.pair_collisions == pairs
    gas.enable_collisions(True)
    assert gas.sim.collisions == "exact"
    gas.sim.run(time=2.0)
    assert gas.sim.counters.pair_collisions > pairs
    assert gas.sim.escaped() == 0


def test_frames_carry_the_piston_and_its_collisions_stay_on():
    session = ViewerSession(preset("piston", n=50), preset="piston")
    session.step()
    frame = protocol.decode_frame(session.frame(1))
    piston = session.sim.piston()
    assert piston is not None
    np.testing.assert_array_equal(
        frame["piston"], session.sim.container.piston_line(piston.position).astype(np.float32)
    )
    with pytest.raises(InputError) as caught:
        session.enable_collisions(False)
    assert caught.value.field == "collisions"
    assert session.sim.collisions == "exact"


def test_the_forces_switch_off_and_on():
    session = ViewerSession(preset("charged-gas", n=50))
    assert session.scene()["has_forces"]
    potential = session.sim.energy().potential
    session.enable_forces(False)
    assert session.sim.forces == () and session.sim.energy().potential == 0.0
    session.enable_forces(True)
    assert session.sim.energy().potential == potential


def test_forces_cannot_be_switched_on_without_any(gas):
    assert not gas.scene()["has_forces"]
    with pytest.raises(InputError, match="forces: this scenario has no forces"):
        gas.enable_forces(True)


def test_set_velocity_and_trace_check_the_index(gas):
    gas.set_velocity(7, 3.0, -4.0)
    np.testing.assert_array_equal(gas.sim.particles.velocity[7], [3.0, -4.0])
    gas.sim.run(steps=1)  # the exact engine takes the edit
    assert gas.sim.escaped() == 0
    with pytest.raises(InputError, match="index: no particle 100; there are 100"):
        gas.set_velocity(100, 0.0, 0.0)
    gas.trace(99)
    assert gas.traced == 99
    with pytest.raises(InputError, match="index"):
        gas.trace(100)


def test_reset_returns_to_the_starting_state(gas):
    start = gas.sim.particles.position.copy()
    generation = gas.generation
    gas.heat(2.0)
    gas.enable_collisions(False)
    gas.sim.run(time=1.0)
    gas.reset()
    np.testing.assert_array_equal(gas.sim.particles.position, start)
    assert gas.sim.time == 0.0 and gas.sim.collisions == "exact"
    assert gas.generation == generation + 1


def test_a_simulation_given_directly_resets_to_its_mode_and_time_when_shown():
    sim = preset("gas", n=30, collisions="off").build()
    sim.run(time=1.5)
    session = ViewerSession(simulation=sim)
    session.enable_collisions(True)
    session.advance(0.3, budget=10.0)
    session.reset()
    assert session.sim.collisions == "off" and not session.collisions_enabled
    assert session.sim.time == 1.5 and session.sim.steps == 150
    assert 'collisions = "off"' in session.export()["toml"]


def test_forces_lower_the_particle_limit():
    with pytest.raises(InputError, match=f"at most {protocol.MAX_CHARGED_PARTICLES} with forces"):
        ViewerSession(preset("charged-gas", n=protocol.MAX_CHARGED_PARTICLES + 2))


def test_a_simulation_given_directly_resets_to_its_state_when_shown():
    sim = preset("gas", n=30).build()
    sim.run(time=1.0)
    start = sim.particles.position.copy()
    session = ViewerSession(simulation=sim)
    session.advance(0.5, budget=10.0)
    session.reset()
    np.testing.assert_array_equal(session.sim.particles.position, start)
    exported = Scenario.from_toml_string(session.export()["toml"]).build()
    np.testing.assert_array_equal(exported.particles.position, start)


def test_load_switches_preset_and_refuses_what_the_files_refuse(gas):
    gas.load("pool-break", {})
    assert gas.sim.particles.n == 225 and gas.scene()["preset"] == "pool-break"
    with pytest.raises(InputError, match="n: must be >= 0"):
        gas.load("gas", {"n": -1})
    with pytest.raises(InputError, match="preset: unknown preset 'nope'"):
        gas.load("nope", {})
    with pytest.raises(InputError, match=f"at most {protocol.MAX_PARTICLES}"):
        gas.load("gas", {"n": protocol.MAX_PARTICLES + 1})  # refused before building
    assert gas.sim.particles.n == 225  # nothing changed by the refusals


def test_a_scenario_from_the_page_is_validated_like_a_file(gas):
    text = preset("gas", n=40).to_toml()
    gas.load_toml(text)
    assert gas.sim.particles.n == 40 and gas.scene()["preset"] is None
    with pytest.raises(InputError, match=r"run\.dt: must be > 0"):
        gas.load_toml(text.replace("dt = 0.01", "dt = -1.0"))
    with pytest.raises(InputError, match="observers: the viewer measures by itself"):
        gas.load_toml(text + '\n[[observers]]\nkind = "trajectory"\npath = "x.gsd"\nevery = 1\n')


def test_export_gives_the_scenario_reset_returns_to(gas):
    exported = gas.export()
    assert exported["filename"] == "gas.toml"
    assert Scenario.from_toml_string(exported["toml"]) == preset("gas", n=100)


def test_pressure_and_collision_rate_are_window_averages(gas):
    gas.stats()
    for _ in range(2):  # two windows: the second starts where the first ended
        thermo = Thermo().compute(gas.sim)
        pairs, start = gas.sim.counters.pair_collisions, gas.sim.time
        for _ in range(WINDOW_SAMPLES):
            gas.sim.run(steps=20)
            thermo.compute(gas.sim, reset=False)
            stats = gas.stats()
        assert stats["pressure_kind"] == "wall"
        assert stats["pressure"] == pytest.approx(thermo.wall_pressure()["total"], rel=1e-12)
        assert stats["pressure_error"] == pytest.approx(thermo.wall_pressure_error(), rel=1e-12)
        expected = (gas.sim.counters.pair_collisions - pairs) / (gas.sim.time - start)
        assert stats["collision_rate"] == pytest.approx(expected, rel=1e-12)


def test_the_histogram_is_a_density_with_the_maxwell_boltzmann_curve(gas):
    histogram = gas.stats()["histogram"]
    edges = np.array(histogram["edges"])
    density = np.array(histogram["density"])
    speeds = np.hypot(*gas.sim.particles.velocity.T)
    inside = np.mean(speeds < edges[-1])
    assert np.sum(density * np.diff(edges)) == pytest.approx(inside, rel=1e-12)
    assert edges[-1] > speeds.mean()
    centres = 0.5 * (edges[1:] + edges[:-1])
    law = MaxwellBoltzmann2D(gas.sim.temperature(), gas.sim.particles.mass)
    np.testing.assert_allclose(histogram["maxwell_boltzmann"], law.pdf(centres), rtol=1e-12)


def test_frames_carry_positions_and_velocities_when_they_are_drawn():
    charged = ViewerSession(preset("charged-gas", n=50), preset="charged-gas")
    assert charged.colour == "charge"  # the preset's guide says so
    plain = protocol.decode_frame(charged.frame(4))
    np.testing.assert_array_equal(plain["position"], charged.sim.particles.position.astype("f4"))
    assert plain["velocity"] is None and plain["generation"] == charged.generation
    charged.momentum = True
    full = protocol.decode_frame(charged.frame(5))
    np.testing.assert_array_equal(full["velocity"], charged.sim.particles.velocity.astype("f4"))
    charged.momentum = False
    charged.set_colour("speed")  # colours from velocities
    assert protocol.decode_frame(charged.frame(6))["velocity"] is not None


def test_colour_modes_are_those_that_apply(gas):
    assert gas.scene()["colour_modes"] == ["speed"]
    with pytest.raises(InputError, match="mode: 'charge' does not apply to this scene"):
        gas.set_colour("charge")
    blocks = ViewerSession(preset("pi-blocks"), preset="pi-blocks")
    scene = blocks.scene()
    assert scene["colour_modes"] == ["speed", "species"] and blocks.colour == "species"
    assert scene["species"] == [0.0, 1.0] and scene["species_labels"] == [
        "mass 1 kg",
        "mass 1e+10 kg",
    ]


def test_the_hello_describes_every_presets_controls_and_explains_it(gas):
    presets = {entry["name"]: entry for entry in gas.hello()["presets"]}
    assert set(presets) == set(PRESETS)
    assert all(entry["explanation"] for entry in presets.values())
    controls = {spec["name"]: spec for spec in presets["heat-flow"]["parameters"]}
    assert controls["hot"] == {"name": "hot", "label": "hot wall kT", "unit": "J",
                               "default": 30.0, "kind": "number"}  # fmt: skip
    assert controls["n"]["kind"] == "integer"
    assert controls["boundary"]["choices"] == ["reflecting", "periodic"]
    assert "seed" not in controls and "tolerance" not in controls
    # Every control the page offers is one the preset takes.
    for name, entry in presets.items():
        for spec in entry["parameters"]:
            preset(name, **{spec["name"]: spec["default"]})


def test_the_cue_ball_is_the_highlighted_disk():
    scene = ViewerSession(preset("pool-break"), preset="pool-break").scene()
    assert scene["highlight"] == 224 and scene["highlight_label"] == "cue ball"
    assert scene["n"] == 225


def test_the_scene_sends_an_l_shaped_vessel_filled_and_its_partition():
    """The page paints the triangles the server sends (an L is not convex) and strokes the
    partitions' pieces, the hole left open."""
    data = {
        "vessel": {"shape": "polygon",
                   "vertices": [[0, 0], [10, 0], [10, 4], [4, 4], [4, 10], [0, 10]],
                   "partitions": [{"name": "p", "start": [2, 0], "end": [2, 10], "gap": 2.0}]},
        "particles": [{"kind": "random", "n": 10, "radius": 0.2}],
    }  # fmt: skip
    vessel = ViewerSession(Scenario.from_dict(data)).scene()["vessel"]
    triangles = np.array(vessel["fill"])
    first, second = triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]
    areas = 0.5 * (first[:, 0] * second[:, 1] - first[:, 1] * second[:, 0])
    assert (areas > 0).all() and areas.sum() == pytest.approx(64.0)  # none outside, all covered
    assert vessel["partition_lines"] == [[[2.0, 0.0], [2.0, 4.0]], [[2.0, 6.0], [2.0, 10.0]]]
    assert vessel["walls"][-1] == "p" and vessel["partitions"][0]["gap"] == 2.0


def test_stats_carry_a_warning_once_the_energy_drifted_past_the_limit(gas):
    assert gas.stats()["warning"] is None
    exploding = ViewerSession(preset("charged-gas", k=5000.0, integrator="fixed"))
    for _ in range(100):
        exploding.step()
        if exploding.stats()["warning"]:
            break
    warning = exploding.stats()["warning"]
    assert warning.startswith("the total energy drifted by") and "(limit 0.001)" in warning
    exploding.reset()
    assert exploding.stats()["warning"] is None


def test_a_step_too_slow_to_watch_pauses_but_the_first_is_not_judged(gas, monkeypatch):
    """The first step also loads the kernels, so only later steps are held to the limit."""
    monkeypatch.setattr(session_module, "MAX_STEP_SECONDS", 0.0)
    gas.advance(0.01, budget=10.0)
    assert gas.sim.steps == 1 and gas.playing
    with pytest.raises(SimulationError, match="too slow to watch"):
        gas.advance(0.01, budget=10.0)
    assert not gas.playing


def test_walls_held_hot_heat_the_gas_and_are_given_back(gas):
    own = gas.sim.container
    kT = gas.sim.temperature()
    gas.hold_wall_temperature(3 * kT)
    assert gas.status()["wall_temperature"] == 3 * kT
    gas.sim.run(time=20.0)
    # The gas takes the walls' temperature (statistical spread of 100 disks: a few percent).
    assert gas.sim.temperature() == pytest.approx(3 * kT, rel=0.15)
    assert abs(gas.stats()["drift"]) < 1e-9  # the heat the walls gave is counted, not drift
    gas.hold_wall_temperature(None)
    assert gas.sim.container is own and gas.status()["wall_temperature"] is None


def test_a_piston_stays_a_piston_while_the_walls_are_held_and_a_periodic_box_refuses():
    piston = ViewerSession(preset("piston", n=50), preset="piston")
    wall = piston.sim.container.piston[0]
    piston.hold_wall_temperature(1.0)
    walls = piston.sim.container.walls
    name = piston.sim.container.wall_names[wall]
    assert type(walls[name]).__name__ == "Piston"
    assert {type(r).__name__ for n, r in walls.items() if n != name} == {"Thermal"}
    assert piston.stats()["piston"]["position"] == piston.sim.piston().position
    periodic = ViewerSession(preset("granular", n=50), preset="granular")
    assert periodic.status()["has_walls"] is False
    with pytest.raises(InputError, match="temperature: a periodic box has no walls"):
        periodic.hold_wall_temperature(1.0)


def test_the_histogram_averages_the_last_readouts_with_the_same_bins(gas):
    gas.set_histogram_window(3)
    densities = []
    for _ in range(4):
        gas.sim.run(steps=5)
        stats = gas.stats()
        gas.stats()  # the same moment again (paused) is not counted twice
        edges = np.array(stats["histogram"]["edges"])
        densities.append(np.histogram(np.hypot(*gas.sim.particles.velocity.T), edges)[0])
    histogram = stats["histogram"]
    assert histogram["readouts"] == 3
    widths = np.diff(edges)
    expected = np.mean([counts / (100 * widths) for counts in densities[-3:]], axis=0)
    np.testing.assert_allclose(histogram["density"], expected, rtol=1e-12, atol=1e-15)


def test_the_followed_disk_is_described(gas):
    gas.trace(7)
    traced = gas.stats()["traced"]
    speed = float(np.hypot(*gas.sim.particles.velocity[7]))
    assert traced["index"] == 7 and traced["speed"] == pytest.approx(speed, rel=1e-15)
    assert traced["kinetic"] == pytest.approx(0.5 * speed**2, rel=1e-15)  # m = 1 kg
    gas.trace(None)
    assert gas.stats()["traced"] is None


def test_a_pump_lets_thermal_particles_in_at_the_hatch_and_out_again(gas):
    before = gas.sim.particles.n
    added = gas.pump(30, kT=4.0)
    p = gas.sim.particles
    assert 0 < added <= 30 and p.n == before + added
    new = slice(before, None)
    # In at the middle of the first wall (the bottom of the box), moving up into it.
    assert np.all(np.abs(p.position[new, 1] + 10.0) < 0.3) and np.all(p.velocity[new, 1] > 0)
    gas.sim.run(steps=200)
    assert gas.sim.escaped() == 0 and gas.scene()["n"] == p.n
    let_out = gas.pump(-40)
    assert let_out == 40 and gas.sim.particles.n == p.n - 40


def test_pumped_speeds_are_those_a_thermal_wall_emits(gas):
    """Normal speeds Rayleigh, tangential Gaussian, at sigma = sqrt(kT / m): KS tests."""
    from scipy import stats

    normal, tangential = [], []
    for seed in range(20):
        session = ViewerSession(preset("gas", n=20, seed=seed), preset="gas")
        start = session.sim.particles.n
        session.pump(100, kT=9.0)
        velocity = session.sim.particles.velocity[start:]
        normal += list(velocity[:, 1])
        tangential += list(velocity[:, 0])
    assert stats.kstest(normal, stats.rayleigh(scale=3.0).cdf).pvalue > 1e-3
    assert stats.kstest(tangential, stats.norm(scale=3.0).cdf).pvalue > 1e-3


def test_a_periodic_box_has_no_hatch():
    periodic = ViewerSession(preset("granular", n=50), preset="granular")
    with pytest.raises(InputError, match="pump: a periodic box has no wall to pump through"):
        periodic.pump(5)


# -- dragging a wall -----------------------------------------------------------------------


def until_the_wall_stops(session: ViewerSession) -> None:
    """Run until the dragged wall has reached its target (a driven piston halts there)."""
    for _ in range(10_000):
        session.sim.run(steps=10)
        state = session.sim.piston()
        if state is not None and state.velocity == 0.0:
            return
    raise AssertionError("the wall never arrived")


def test_dragging_a_wall_in_heats_a_dilute_gas_along_its_adiabat_and_out_cools_it():
    """T A is constant for a slowly compressed dilute 2D gas (2 degrees of freedom): halving the
    area doubles kT. The wall moves at a fifth of the rms speed: its irreversible heating adds
    a few percent, within the 10% allowed. The work it does is counted as the wall's heat. Back
    out, the gas cools, but over the cycle the wall has done work on it (the second law)."""
    gas = ViewerSession(preset("gas", n=400, radius=0.05), preset="gas")
    assert gas.scene()["movable_wall"]["name"] == "right"
    kT = gas.sim.temperature()
    gas.move_wall(0.0)  # the right wall from x = 10 m to 0: half the area
    gas.move_wall(None)  # let go: a box's wall goes on to where it was sent
    until_the_wall_stops(gas)
    state = gas.sim.piston()
    assert state.position == 0.0 and np.all(gas.sim.particles.position[:, 0] < 0.0)
    assert gas.sim.temperature() / kT == pytest.approx(2.0, rel=0.1)
    assert state.work == pytest.approx(gas.sim.energy().kinetic - 400 * kT, rel=1e-12)
    assert abs(gas.stats()["drift"]) < 1e-12
    compressed = gas.sim.temperature()
    gas.move_wall(10.0)
    until_the_wall_stops(gas)
    assert gas.sim.temperature() < 0.6 * compressed
    assert gas.sim.piston().work > 0.0 and gas.sim.temperature() > kT


def test_a_drag_stops_where_the_gas_would_be_squeezed_too_dense():
    gas = ViewerSession(preset("gas", n=200), preset="gas")
    wall = gas.scene()["movable_wall"]
    gas.move_wall(-1e9)
    until_the_wall_stops(gas)
    assert gas.sim.piston().position == wall["low"] > -10.0
    area = (wall["low"] + 10.0) * 20.0
    disks = float(np.sum(np.pi * gas.sim.particles.radius**2))
    assert disks / area == pytest.approx(moving_wall.MAX_PACKING, rel=1e-12)
    assert gas.sim.escaped() == 0


def test_a_free_piston_is_driven_while_dragged_and_free_once_let_go():
    piston = ViewerSession(preset("piston", n=50), preset="piston")
    piston.sim.run(steps=5)
    start = piston.sim.piston().position
    piston.move_wall(start - 5.0)
    assert piston.sim.container.piston[1].driven
    until_the_wall_stops(piston)
    assert piston.sim.piston().position == pytest.approx(start - 5.0, abs=1e-12)
    piston.move_wall(None)
    own = piston.sim.container.piston[1]
    assert not own.driven and own.mass == 20.0
    assert piston.sim.piston().position == pytest.approx(start - 5.0, abs=1e-12)
    piston.sim.run(steps=50)  # the weight and the gas move it again
    assert piston.sim.piston().velocity != 0.0


def test_a_moved_wall_stays_while_the_walls_are_held_hot():
    gas = ViewerSession(preset("gas", n=100), preset="gas")
    gas.move_wall(5.0)
    until_the_wall_stops(gas)
    gas.hold_wall_temperature(2.0)
    walls = gas.sim.container.walls
    assert type(walls["right"]).__name__ == "Piston"
    assert {type(walls[name]).__name__ for name in ("left", "bottom", "top")} == {"Thermal"}
    gas.sim.run(steps=20)
    gas.hold_wall_temperature(None)
    assert gas.sim.piston().position == 5.0 and gas.sim.container.walls["right"].driven


def test_only_a_box_in_the_exact_engine_without_forces_has_a_wall_to_drag():
    for name in ("charged-gas", "circle-gas", "hard-disks"):
        session = ViewerSession(preset(name), preset=name)
        assert session.scene()["movable_wall"] is None, name
        with pytest.raises(InputError, match="wall: only a box with exact collisions"):
            session.move_wall(1.0)


def test_the_hatch_stays_on_the_gas_side_of_a_moved_wall():
    """With the right wall moved in to x = -4 m, the hatch is the middle of what is left of the
    bottom wall, x = -7 m, and the particles pumped in arrive there."""
    gas = ViewerSession(preset("gas", n=50), preset="gas")
    gas.move_wall(-4.0)
    until_the_wall_stops(gas)
    before = gas.sim.particles.n
    assert gas.pump(10, kT=4.0) > 5  # those that would overlap a disk near the hatch wait
    arrived = gas.sim.particles.position[before:]
    spacing = 2.0 * 0.25 * 1.05  # the row of ten along the wall, centred on the hatch
    assert np.all(np.abs(arrived[:, 0] + 7.0) <= 5 * spacing) and np.all(arrived[:, 0] < -4.25)
