"""Scenario schema: TOML round trips, one-line errors, overrides, bitwise-reproducible builds."""

from __future__ import annotations

import math
import struct
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pydantic import ValidationError

from collidium.errors import InputError
from collidium.forces.pair import MAX_SOFTENING
from collidium.presets import preset, presets
from collidium.scenario import (
    FASTEST_COMPONENT,
    Scenario,
    apply_overrides,
    describe,
    dump_toml,
)
from collidium.simulation import Simulation

# --- strategies ----------------------------------------------------------------------------------

finite = st.floats(allow_nan=False, allow_infinity=False)
positive = st.floats(min_value=0.0, exclude_min=True, allow_infinity=False)
non_negative = st.floats(min_value=0.0, allow_infinity=False)
vector = st.lists(finite, min_size=2, max_size=2)


def per_particle(values: st.SearchStrategy[float], n: int) -> st.SearchStrategy[Any]:
    return st.one_of(values, st.lists(values, min_size=n, max_size=n))


@st.composite
def explicit_groups(draw: st.DrawFn) -> dict[str, Any]:
    position = draw(st.lists(vector, min_size=1, max_size=4))
    n = len(position)
    group: dict[str, Any] = {"kind": "explicit", "position": position}
    if draw(st.booleans()):
        group["velocity"] = draw(st.lists(vector, min_size=n, max_size=n))
    group["mass"] = draw(per_particle(positive, n))
    group["radius"] = draw(per_particle(non_negative, n))
    group["charge"] = draw(per_particle(finite, n))
    return group


random_groups = st.fixed_dictionaries(
    {"kind": st.just("random"), "n": st.integers(0, 10**6)},
    optional={
        "mass": positive,
        "radius": non_negative,
        "speed": st.floats(0.0, FASTEST_COMPONENT, exclude_max=True),
        "charge": finite,
        "charges": st.sampled_from(["same", "balanced"]),
    },
)
rack_groups = st.fixed_dictionaries(
    {"kind": st.just("rack")},
    optional={
        "apex": vector,
        "rows": st.integers(1, 50),
        "radius": positive,
        "mass": positive,
        "gap": non_negative,
        "charge": finite,
        "back_tip": st.booleans(),
    },
)
coulombs = st.fixed_dictionaries(
    {"type": st.just("coulomb")},
    optional={
        "k": finite,
        "softening": st.floats(0.0, MAX_SOFTENING),
        "max_acceleration": positive,
    },
)
scenario_dicts = st.fixed_dictionaries(
    {
        "particles": st.lists(
            st.one_of(explicit_groups(), random_groups, rack_groups), min_size=1, max_size=3
        )
    },
    optional={
        "name": st.text(max_size=20),
        "description": st.text(max_size=40),
        "seed": st.integers(0, 2**63 - 1),
        "vessel": st.one_of(
            st.fixed_dictionaries(
                {},
                optional={
                    "shape": st.just("box"),
                    "width": positive,
                    "height": positive,
                    "boundary": st.sampled_from(["reflecting", "periodic"]),
                },
            ),
            st.fixed_dictionaries({"shape": st.just("circle")}, optional={"radius": positive}),
        ),
        "run": st.fixed_dictionaries(
            {},
            optional={
                "dt": positive,
                "time": non_negative,
                "collisions": st.sampled_from(["exact", "step", "off"]),
            },
        ),
        "forces": st.lists(coulombs, max_size=2),
    },
)


def bits(value: Any) -> Any:
    """The data with every float replaced by its bit pattern (so -0.0 != 0.0, exact compare)."""
    if isinstance(value, dict):
        return {key: bits(item) for key, item in value.items()}
    if isinstance(value, list):
        return [bits(item) for item in value]
    if isinstance(value, float):
        return ("float", struct.pack("<d", value))
    return value


# --- TOML round trips ----------------------------------------------------------------------------


@settings(max_examples=200, suppress_health_check=[HealthCheck.too_slow])
@given(scenario_dicts)
def test_toml_round_trip_is_bitwise(data):
    scenario = Scenario.from_dict(data)
    again = Scenario.from_toml_string(scenario.to_toml())
    assert bits(again.to_dict()) == bits(scenario.to_dict())
    assert again == scenario


@given(scenario_dicts)
def test_validated_values_keep_their_input_floats(data):
    scenario = Scenario.from_dict(data)
    for group_in, group_out in zip(data["particles"], scenario.to_dict()["particles"], strict=True):
        for key, value in group_in.items():
            if isinstance(value, float):
                assert struct.pack("<d", group_out[key]) == struct.pack("<d", value)


def test_toml_file_round_trip(tmp_path):
    scenario = preset("bohr-atom")
    path = tmp_path / "atom.toml"
    path.write_text(scenario.to_toml())
    assert Scenario.from_toml(path) == scenario


def test_written_toml_is_compact_and_readable():
    text = preset("head-on").to_toml()
    assert "position = [\n    [-1.0, 0.0],\n    [1.0, 0.0],\n]" in text
    assert text.index("[vessel]") < text.index("[run]") < text.index("[[particles]]")


def test_dump_toml_scalars_and_strings_are_escaped():
    text = dump_toml({"name": 'a "quoted"\nline', "x": [1.5, -0.0], "t": {"b": True}})
    import tomllib

    assert tomllib.loads(text) == {"name": 'a "quoted"\nline', "x": [1.5, -0.0], "t": {"b": True}}


# --- one-line errors -----------------------------------------------------------------------------

GAS = {"particles": [{"kind": "random", "n": 3}]}


def with_field(path: str, value: Any) -> dict[str, Any]:
    """GAS plus a value set at a dotted path (tables created on the way)."""
    data: dict[str, Any] = {
        "particles": [{"kind": "random", "n": 3}],
        "forces": [{"type": "coulomb"}],
    }
    node: Any = data
    parts = path.split(".")
    for part in parts[:-1]:
        node = node[int(part)] if part.isdigit() else node.setdefault(part, {})
    node[parts[-1]] = value
    return data


@pytest.mark.parametrize(
    "path", ["colour", "vessel.depth", "run.steps", "forces.0.power", "particles.0.velocity"]
)
def test_extra_fields_are_rejected_and_named(path):
    with pytest.raises(InputError) as info:
        Scenario.from_dict(with_field(path, 1))
    assert info.value.field == path
    assert info.value.reason.startswith("unknown field; allowed:")


@pytest.mark.parametrize(
    ("path", "value", "reason"),
    [
        ("run.dt", 0.0, "must be > 0"),
        ("run.dt", -1.0, "must be > 0"),
        ("run.dt", math.nan, "finite"),
        ("run.time", math.inf, "finite"),
        ("run.collisions", "fast", "'exact', 'step' or 'off'"),
        ("vessel.width", 0, "must be > 0"),
        ("vessel.boundary", "open", "'reflecting' or 'periodic'"),
        ("vessel.shape", "torus", "unknown value 'torus'; choose from box, circle"),
        ("seed", -1, "must be >= 0"),
        ("seed", 1.5, "integer"),
        ("seed", 2**63, "must be <= 9223372036854775807"),
        ("particles.0.n", -3, "must be >= 0"),
        ("particles.0.n", True, "integer"),
        ("particles.0.n", "3", "integer"),
        ("particles.0.mass", -1.0, "must be > 0"),
        ("particles.0.radius", -0.1, "must be >= 0"),
        ("particles.0.speed", math.nan, "finite"),
        ("particles.0.speed", 2.2e8, "below the speed of light"),  # sqrt(2) 2.2e8 > 3e8 m/s
        ("particles.0.charges", "random", "'same' or 'balanced'"),
        ("forces.0.softening", -0.5, "must be >= 0"),
        ("forces.0.max_acceleration", 0.0, "must be > 0"),
    ],
)
def test_invalid_values_name_the_field(path, value, reason):
    with pytest.raises(InputError) as info:
        Scenario.from_dict(with_field(path, value))
    assert info.value.field == path
    assert reason in info.value.reason
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("group", "field", "reason"),
    [
        ({"position": [[0, 0]], "mass": -1}, "particles.0.mass", "must be > 0"),
        ({"position": [[0, 0], [1, 1]], "mass": [1, 0]}, "particles.0.mass", "element 1"),
        ({"position": [[0, 0], [1, 1]], "radius": [0.1]}, "particles.0.radius", "has 1 entries"),
        ({"position": [[0, 0]], "charge": "x"}, "particles.0.charge", "must be a number"),
        ({"position": [[0, 0], [1, 2, 3]]}, "particles.0.position.1", "at most 2"),
        ({"position": [[0, math.nan]]}, "particles.0.position.0.1", "finite"),
        ({"position": [[0, 0]], "velocity": [[0, 0], [1, 1]]}, "particles.0.velocity", "entries"),
        ({"position": []}, "particles.0.position", "at least 1"),
    ],
)
def test_explicit_group_errors(group, field, reason):
    with pytest.raises(InputError) as info:
        Scenario.from_dict({"particles": [{"kind": "explicit", **group}]})
    assert info.value.field == field
    assert reason in info.value.reason


def test_group_kind_missing_or_unknown():
    with pytest.raises(InputError, match=r"^particles\.0\.kind: missing; choose from explicit"):
        Scenario.from_dict({"particles": [{"n": 3}]})
    with pytest.raises(InputError, match=r"^particles\.0\.kind: unknown value 'gas'"):
        Scenario.from_dict({"particles": [{"kind": "gas"}]})
    with pytest.raises(InputError, match=r"^forces\.0\.type: unknown value 'yukawa'; choose from"):
        Scenario.from_dict({**GAS, "forces": [{"type": "yukawa"}]})


def test_describe_gives_one_line():
    try:
        Scenario.model_validate({"run": {"dt": -1.0}, "particles": [{"kind": "random", "n": 3}]})
    except ValidationError as exc:
        assert describe(exc) == "run.dt: must be > 0, got -1.0"
    else:  # pragma: no cover
        pytest.fail("no validation error")


def test_bad_toml_names_file_and_line(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text('name = "x"\n\n[box\nwidth = 3\n')
    with pytest.raises(InputError) as info:
        Scenario.from_toml(path)
    assert info.value.field == str(path)
    assert "line 3" in info.value.reason


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        Scenario.from_toml(tmp_path / "nope.toml")


# --- building ------------------------------------------------------------------------------------


def explicit(position, **extra):
    return {"particles": [{"kind": "explicit", "position": position, **extra}]}


def test_overlap_is_refused_and_named():
    with pytest.raises(InputError) as info:
        Scenario.from_dict(explicit([[0, 0], [3, 3], [0.3, 0]])).build()
    assert info.value.field == "particles.0.position.2"
    assert "overlaps particles.0.position.0" in info.value.reason


def test_overlap_allowed_without_collisions():
    data = explicit([[0, 0], [0.3, 0]]) | {"run": {"collisions": "off"}}
    assert Scenario.from_dict(data).build().particles.n == 2


def test_outside_is_refused_and_named():
    with pytest.raises(InputError) as info:
        Scenario.from_dict(explicit([[0, 0], [9.9, 0]])).build()
    assert info.value.field == "particles.0.position.1"
    assert "outside the 20 x 20 box" in info.value.reason


def test_periodic_box_wraps_instead_of_refusing():
    data = explicit([[0, 0], [10.5, 0]]) | {"vessel": {"boundary": "periodic"}}
    sim = Scenario.from_dict(data).build()
    assert sim.particles.position[1, 0] == pytest.approx(-9.5)


def test_too_dense_random_group_is_named():
    data = {"particles": [{"kind": "random", "n": 10}, {"kind": "random", "n": 5000}]}
    with pytest.raises(InputError) as info:
        Scenario.from_dict(data).build()
    assert info.value.field == "particles.1.n"


def test_random_groups_avoid_every_listed_particle():
    data = {
        "particles": [
            {"kind": "random", "n": 150, "radius": 0.3},
            {"kind": "explicit", "position": [[0.0, 0.0]], "radius": 4.0},
        ]
    }
    sim = Scenario.from_dict(data).build()
    distance = np.hypot(*sim.particles.position[:150].T)
    assert (distance >= 4.3).all()
    assert sim.particles.radius[150] == 4.0


def test_groups_concatenate_in_order_with_their_properties():
    data = {
        "forces": [{"type": "coulomb", "k": 2.0, "softening": 0.1}],
        "particles": [
            {"kind": "explicit", "position": [[-5, 0], [5, 0]], "mass": [2, 3], "charge": -1},
            {
                "kind": "random",
                "n": 10,
                "mass": 0.5,
                "speed": 2,
                "charge": 1,
                "charges": "balanced",
            },
            {"kind": "rack", "apex": [-8, -8], "rows": 2, "radius": 0.2},
        ],
    }
    sim = Scenario.from_dict(data).build()
    p = sim.particles
    assert p.n == 2 + 10 + 3
    assert list(p.mass[:2]) == [2.0, 3.0] and (p.mass[2:12] == 0.5).all()
    assert list(p.charge[:2]) == [-1.0, -1.0] and p.charge[2:12].sum() == 0
    assert (np.abs(p.velocity[2:12]) <= 2).all() and (p.velocity[12:] == 0).all()
    assert (p.radius[12:] == 0.2).all()
    (force,) = sim.forces
    assert (force.k, force.softening, force.max_acceleration) == (2.0, 0.1, None)


def state_bytes(sim: Simulation) -> tuple[Any, ...]:
    p = sim.particles
    arrays = (p.position, p.velocity, p.mass, p.radius, p.charge)
    return (
        *(a.tobytes() for a in arrays),
        sim.container.to_dict(),
        sim.forces,
        sim.dt,
        sim.collisions,
        sim.seed,
        sim.name,
    )


def test_building_twice_is_bitwise_identical():
    scenario = preset("charged-gas", n=300, seed=9)
    assert state_bytes(scenario.build()) == state_bytes(scenario.build())


@pytest.mark.parametrize("name", presets())
def test_export_then_load_every_preset_is_bitwise_identical(name, tmp_path):
    scenario = preset(name)
    path = tmp_path / f"{name}.toml"
    path.write_text(scenario.to_toml())
    loaded = Scenario.from_toml(path)
    original, reloaded = scenario.build(), loaded.build()
    assert state_bytes(reloaded) == state_bytes(original)
    # ...and so is the run that follows.
    assert state_bytes(reloaded.run(time=1.0)) == state_bytes(original.run(time=1.0))


# --- overrides -----------------------------------------------------------------------------------


def test_apply_overrides_sets_dotted_paths_and_validates():
    data = preset("gas").to_dict()
    out = apply_overrides(
        data, {"run.dt": 0.005, "particles.0.n": 300, "vessel.boundary": "periodic"}
    )
    assert out["run"]["dt"] == 0.005
    assert out["particles"][0]["n"] == 300
    assert out["vessel"]["boundary"] == "periodic"
    assert data["run"]["dt"] == 0.01  # the input is not modified


def test_apply_overrides_creates_missing_tables():
    out = apply_overrides(GAS, {"vessel.width": 30.0})
    assert out["vessel"] == {
        "shape": "box",
        "width": 30.0,
        "height": 20.0,
        "boundary": "reflecting",
    }


@pytest.mark.parametrize(
    ("overrides", "field", "reason"),
    [
        ({"particles.4.n": 3}, "particles.4", "no entry 4"),
        ({"particles.first.n": 3}, "particles.first", "list index"),
        ({"run.dt": 0.0}, "run.dt", "must be > 0"),
        ({"run.dtt": 0.1}, "run.dtt", "unknown field"),
        ({"particles.0.n": 2.5}, "particles.0.n", "integer"),
        ({"seed.x": 1}, "seed.x", "is a value"),
        ({"run..dt": 1}, "run..dt", "not a field path"),
    ],
)
def test_apply_overrides_errors_name_the_path(overrides, field, reason):
    with pytest.raises(InputError) as info:
        apply_overrides(preset("gas").to_dict(), overrides)
    assert info.value.field == field
    assert reason in info.value.reason


def test_with_overrides_returns_a_new_scenario():
    base = preset("gas")
    changed = base.with_overrides({"particles.0.speed": 3.0, "seed": 4})
    assert changed.to_dict()["particles"][0]["speed"] == 3.0 and changed.seed == 4
    assert base.to_dict()["particles"][0]["speed"] == 10.0 and base.seed == 1


def test_numpy_values_are_accepted():
    data = {"seed": np.int64(3), "particles": [{"kind": "explicit", "position": np.zeros((1, 2))}]}
    scenario = Scenario.from_dict(data)
    assert scenario.seed == 3 and type(scenario.seed) is int
    assert scenario.to_dict()["particles"][0]["position"] == [[0.0, 0.0]]


def test_random_disks_clear_the_periodic_images_of_listed_ones():
    data = {
        "vessel": {"boundary": "periodic"},
        "particles": [
            {"kind": "explicit", "position": [[9.95, 0.0]]},
            {"kind": "random", "n": 600},
        ],
    }
    sim = Scenario.from_dict(data).build()  # overlaps across the edge would be refused here
    assert sim.particles.n == 601


OBSERVERS = """
[[observers]]
kind = "speeds"
interval = 0.5
after = 2.0
bins = 20
range = [0.0, 20.0]

[[observers]]
kind = "thermo"
every = 10

[[observers]]
kind = "tracer"
particles = [0, 3]

[[observers]]
kind = "trajectory"
path = "{path}"
every = 50
"""


def test_observers_from_the_scenario_file(tmp_path):
    import collidium as cd
    from collidium.io.trajectory import read_trajectory
    from collidium.loading import load_scenario
    from collidium.observers import SpeedHistogram, Thermo, Tracer

    text = load_scenario("gas").to_toml() + OBSERVERS.format(path=tmp_path / "run.gsd")
    file = tmp_path / "gas.toml"
    file.write_text(text)
    sim = cd.load(file)
    speeds, thermo, tracer, writer = sim.observers
    assert isinstance(speeds, SpeedHistogram) and speeds.bin_edges[-1] == 20.0
    sim.run(time=5.0)
    writer.close()
    assert speeds.frames == 7  # t = 2.0, 2.5, ..., 5.0
    assert isinstance(thermo, Thermo) and thermo.duration == pytest.approx(5.0)
    assert isinstance(tracer, Tracer) and tracer.path.shape == (501, 2, 2)
    assert read_trajectory(tmp_path / "run.gsd").frames == 11
    # Written back out and read again, the scenario is the same.
    assert Scenario.from_toml_string(load_scenario(file).to_toml()) == load_scenario(file)


@pytest.mark.parametrize(
    ("table", "field"),
    [
        ('kind = "speeds"\nevery = 2\ninterval = 1.0', "observers.0.interval"),
        ('kind = "speeds"\nrange = [5.0, 1.0]', "observers.0.range"),
        ('kind = "histogram"', "observers.0.kind"),
        ('kind = "trajectory"\npath = "run.txt"', "observers.0.path"),
        ('kind = "trajectory"', "observers.0.path"),
        ('kind = "thermo"\nevery = 0', "observers.0.every"),
        ('kind = "tracer"\nparticles = [-1]', "observers.0.particles.0"),
    ],
)
def test_bad_observer_tables_name_the_field(table, field):
    from collidium.loading import load_scenario

    text = load_scenario("gas").to_toml() + "\n[[observers]]\n" + table + "\n"
    with pytest.raises(InputError) as caught:
        Scenario.from_toml_string(text)
    assert caught.value.field == field


def test_a_random_group_placed_in_a_region_and_a_bad_region_named():
    table = {"particles": [{"kind": "random", "n": 50, "region": [[2.0, -10.0], [10.0, 0.0]]}]}
    p = Scenario.from_dict(table).build().particles
    assert (p.position[:, 0] >= 2.25).all() and (p.position[:, 1] <= -0.25).all()
    for region in ([[2.0, 0.0], [1.0, 3.0]], [[0.0, 0.0]], [[0.0, 0.0], [1.0, float("nan")]]):
        with pytest.raises(InputError) as caught:
            Scenario.from_dict({"particles": [{"kind": "random", "n": 5, "region": region}]})
        assert caught.value.field.startswith("particles.0.region")


def test_an_effusion_observer_must_watch_a_partition_of_the_vessel():
    from collidium.observers import Effusion

    data = {"vessel": {"partitions": [{"name": "wall", "start": [0.0, -10.0], "end": [0.0, 10.0],
                                       "gap": 1.0}]},
            "particles": [{"kind": "random", "n": 5, "region": [[-10.0, -10.0], [0.0, 10.0]]}],
            "observers": [{"kind": "effusion", "partition": "wall"}]}  # fmt: skip
    (observer,) = Scenario.from_dict(data).build().observers
    assert isinstance(observer, Effusion) and observer.partition == "wall"
    data["observers"] = [{"kind": "effusion", "partition": "door"}]
    with pytest.raises(InputError) as caught:
        Scenario.from_dict(data).build()
    assert caught.value.field == "observers.0.partition"
    assert caught.value.reason == "the vessel has no partition 'door' (it has: wall)"


def test_particles_beyond_the_memory_available_are_refused_before_any_allocation(monkeypatch):
    from collidium import scenario

    monkeypatch.setattr(scenario, "available_memory", lambda: 2**30)
    huge = Scenario.from_dict({"particles": [{"kind": "rack", "rows": 10_000}]})
    with pytest.raises(InputError) as caught:
        huge.build()
    assert caught.value.field == "particles"
    assert caught.value.reason == (
        "99999999 particles need about 37.3 GiB of memory; 1 GiB is available"
    )
    Scenario.from_dict({"particles": [{"kind": "random", "n": 1000}]}).build()  # 0.4 MB: fine
