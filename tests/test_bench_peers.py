"""benchmarks/peers.py: the REBOUND and pymunk peer workloads return sane, JSON-ready figures."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))

import peers  # noqa: E402  (the benchmarks folder is not a package)


def test_imports_and_reports_without_the_peers():
    # None in sys.modules makes `import rebound` fail, as if it were not installed.
    code = (
        "import sys; sys.modules['rebound'] = None; sys.modules['pymunk'] = None; "
        f"sys.path.insert(0, {str(BENCHMARKS)!r}); import peers; print(peers.available())"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "{'rebound': None, 'pymunk': None}"


def test_available_names_each_peer():
    versions = peers.available()
    assert set(versions) == {"rebound", "pymunk"}
    assert all(v is None or isinstance(v, str) for v in versions.values())


def test_jittered_lattice_has_no_overlaps_even_across_periodic_edges():
    n, radius = 500, 0.25
    side = peers.gas_box_side(n, 0.3, radius)
    x = peers.jittered_lattice(n, side, radius, np.random.default_rng(3))
    assert x.shape == (n, 2) and np.all((x > radius) & (x < side - radius))
    d = x[:, None, :] - x[None, :, :]
    d -= side * np.round(d / side)
    dist = np.hypot(d[..., 0], d[..., 1]) + np.eye(n) * side
    assert dist.min() > 2 * radius


def test_enskog_rate_at_packing_0_3():
    # 2 sigma n g sqrt(pi T): sigma = 0.5, n = 1.528, g = 1.773 (Henderson), T = 1.
    assert peers.enskog_collision_rate(0.3, 0.25, 1.0) == pytest.approx(4.80, abs=0.01)


def test_rebound_hard_disks_counts_collisions_at_the_enskog_rate():
    pytest.importorskip("rebound")
    # Long enough (~10 time units) that a gas left to drift out of the plane would have stopped
    # colliding: the z-flattening must keep the rate up.
    result = peers.rebound_hard_disks(200, target_collisions=6000, max_seconds=3.0)
    json.dumps(result)
    assert result["boundary"] == "periodic"
    assert result["collisions"] >= 6000
    assert result["simulated_time"] > 8.0
    assert result["collisions_per_second"] > 0 and result["particle_steps_per_second"] > 0
    assert result["dt"] * result["rms_speed"] == pytest.approx(0.05 * 0.25)
    assert 0.85 < result["fraction_of_enskog"] < 1.1


def test_direct_accelerations_match_rebound_basic():
    pytest.importorskip("rebound")
    position = peers._uniform_square(300, seed=4)
    sim = peers._rebound_gravity_sim(position, "basic", 0.0, 0.01, 1e-3)
    sim.steps(1)  # at rest: the forces are those at `position`
    index = np.arange(0, 300, 7)
    exact = peers.direct_accelerations(position, 1.0 / 300, index, 0.01)
    np.testing.assert_allclose(peers._rebound_acceleration(sim)[index], exact, rtol=1e-9)


def test_rebound_gravity_basic_and_tree():
    pytest.importorskip("rebound")
    basic = peers.rebound_gravity(400, "basic", steps=5)
    json.dumps(basic)
    assert basic["measured"] and basic["steps"] == 5
    assert basic["pair_interactions_per_second"] > 0 and basic["us_per_particle_step"] > 0

    fine = peers.rebound_gravity(800, "tree", steps=3, theta=0.1)
    coarse = peers.rebound_gravity(800, "tree", steps=3, theta=0.5)
    json.dumps(fine)
    assert fine["opening_angle2"] == pytest.approx(0.01)
    assert fine["force_error_rms"] < 1e-3 < coarse["force_error_rms"] < 0.1
    assert fine["particle_steps_per_second"] > 0


def test_rebound_theta_for_matched_accuracy_shrinks_with_n():
    thetas = [peers.rebound_theta_1e3(n) for n in (1000, 5000, 10_000, 100_000, 10**6)]
    assert thetas == sorted(thetas, reverse=True) and 0.05 < thetas[-1] <= thetas[0] < 0.2


def test_rebound_gravity_declines_a_hopeless_run():
    pytest.importorskip("rebound")
    result = peers.rebound_gravity(200_000, "basic", max_seconds=0.01)
    json.dumps(result)
    assert result["measured"] is False and result["steps"] == 0
    assert result["seconds_per_step"] > 0.02  # 4e10 pair terms cannot take less


def test_rebound_opening_angle_scan_error_grows_with_angle():
    pytest.importorskip("rebound")
    scan = peers.rebound_opening_angle_scan(600, thetas=(0.1, 0.3, 0.7))
    json.dumps(scan)
    errors = [s["force_error_rms"] for s in scan["scan"]]
    assert errors == sorted(errors) and errors[0] < 1e-3
    assert scan["theta_for_target"] == 0.1


def test_pymunk_balls():
    pytest.importorskip("pymunk")
    result = peers.pymunk_balls(300, steps=50)
    json.dumps(result)
    assert result["isolated"] is False and result["steps"] == 50
    assert result["particle_steps_per_second"] > 0
    assert result["wall_seconds_per_simulated_second"] == pytest.approx(
        result["seconds"] / (50 * 0.01)
    )
    assert abs(result["kinetic_energy_drift"]) < 1e-2  # elastic, frictionless
    hashed = peers.pymunk_balls(300, max_seconds=0.2, spatial_hash=0.5)
    assert hashed["broadphase"].startswith("spatial hash")
    assert hashed["steps"] >= 1 and math.isfinite(hashed["seconds_per_step"])


def test_pymunk_balls_in_a_child_process():
    pytest.importorskip("pymunk")
    result = peers.pymunk_balls(200, steps=10, isolate=True)
    assert result["isolated"] is True and result["steps"] == 10 and result["n"] == 200
    assert result["particle_steps_per_second"] > 0


def test_bench_gravity_times_the_same_law_as_rebound():
    """collidium's Newton on the benchmark's square gives peers.direct_accelerations (REBOUND's
    law, checked above against REBOUND itself), and the benchmark reports sane figures."""
    import bench_gravity
    import collidium as cd
    from collidium.forces import ForceField

    position = peers._uniform_square(300, seed=4)
    particles = cd.Particles(position, mass=1.0 / 300, radius=0.0)
    newton = cd.Newton(G=1.0, softening=bench_gravity.SOFTENING, method="direct")
    ours = ForceField((newton,)).evaluate(particles, cd.Box(30, 30))
    exact = peers.direct_accelerations(position, 1.0 / 300, np.arange(300), 0.01)
    np.testing.assert_allclose(ours, exact, rtol=1e-10, atol=1e-12 * np.abs(exact).max())
    row = bench_gravity.newton_step(600, "tree", max_seconds=0.05)
    json.dumps(row)
    assert row["force_error_rms"] < 1e-3 and row["us_per_particle_step"] > 0
