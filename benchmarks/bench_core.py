"""Scale and speed benchmarks, beside REBOUND and pymunk where installed (``pip install .[bench]``).

Run: ``python benchmarks/bench_core.py [--quick]``. Prints a table and writes
``benchmarks/results/core.json``. Every timing follows a warm-up run, so compilation is not counted.

W1  exact hard-disk gas at packing 0.3 (one core): pair collisions per second, N = 1e3 .. 1e6; the
    all-pairs NumPy twin at N = 1e3; REBOUND hard spheres with its tree collision search.
W1s ``step`` mode, same gas, dt = 0.01 s (all cores): particle-steps per second; pymunk balls in a
    box at the same N and dt.
W2  charged gas (all cores): microseconds per particle-step of the Coulomb sum, direct and tree,
    N = 200 .. 1e6, with the tree's RMS relative force error; direct pair interactions per second,
    of a kick's sum (forces alone) and of one with the energies; REBOUND direct ("basic") and tree
    gravity at equal N.
W4  the charged-gas preset scaled to N = 1e4 .. 1e5 at its density, tree sum and exact collisions
    (all cores): microseconds per particle-step at its dt = 0.01 s, with the fixed and the
    adaptive integrator, and the queues built or refreshed per step (one per substep).
W4k a gas of 1e5 disks at packing 0.3 whose hundredth are ions in a uniform field, exact collisions
    (all cores): milliseconds per step of dt = 0.01 s with the queue kept and the kicked disks
    predicted again, beside the same steps with the queue built afresh at each kick and beside
    the gas without the field; the disks predicted again per step.
W3  the seed report's scenes (every preset): wall seconds per simulated second, quiet and beside
    one CPU-bound process per core (started and stopped here), and the ratio of the speeds.
M   peak resident memory of an exact run at N = 1e6, and per particle.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba
import numpy as np

import collidium as cd
from collidium.forces import TREE_CROSSOVER
from collidium.initial import random_positions
from collidium.kernels import reference, tree
from collidium.kernels.pairwise import inverse_distance_direct
from collidium.observers import EnergyDrift
from collidium.presets import PRESETS, preset

sys.path.insert(0, str(Path(__file__).parent))
import peers
from machine import busy_cores

RESULTS = Path(__file__).parent / "results"
PACKING = 0.3
RADIUS = 0.25


def packed_gas(
    n: int,
    packing: float = PACKING,
    radius: float = RADIUS,
    seed: int = 1,
    collisions: str = "exact",
    dt: float = 1.0,
    vessel: cd.vessels.Vessel | None = None,
) -> cd.Simulation:
    """N disks at the given packing fraction (of the vessel's area) in ``vessel`` (default: a
    square reflecting box of that area), velocities N(0, 1) m/s."""
    if vessel is None:
        side = peers.gas_box_side(n, packing, radius)
        vessel = cd.Box(side, side)
    rng = np.random.default_rng(seed)
    position = random_positions(n, np.full(n, radius), vessel, rng)
    velocity = rng.normal(0.0, 1.0, (n, 2))
    particles = cd.Particles(position, velocity, radius=radius)
    return cd.Simulation(vessel, particles, dt=dt, collisions=collisions)  # type: ignore[arg-type]


def exact_collisions_per_second(
    n: int,
    target: float,
    repeats: int = 3,
    vessel: cd.vessels.Vessel | None = None,
    warmed: Callable[[], None] = lambda: None,
) -> dict[str, Any]:
    """W1: time the exact engine (one thread) over about ``target`` pair collisions, ``repeats``
    times in a row; the rate is the median (memory-bound timings vary from run to run).
    ``warmed`` is called between the warm-up and the timing (`bench_paired` waits there)."""
    sim = packed_gas(n, vessel=vessel)
    sim.dt = 0.2
    sim.run(steps=1)  # warm-up: compile, build the queue, relax the random start
    sim.dt = max(target / max(sim.counters.pair_collisions / 0.2, 1.0), 1e-3)
    warmed()
    rates = []
    for _ in range(repeats):
        before = sim.counters.pair_collisions
        start = time.perf_counter()
        sim.run(steps=1)
        rates.append((sim.counters.pair_collisions - before) / (time.perf_counter() - start))
    return {"n": n, "per_second": float(np.median(rates)), "repeats": rates}


def numpy_twin_collisions_per_second(n: int, duration: float) -> float:
    """W1 peer: the NumPy twin (all pairs at every event) on the same kind of gas."""
    sim = packed_gas(n)
    p = sim.particles
    half = 0.5 * sim.container.size
    start = time.perf_counter()
    pairs, *_ = reference.event_drift(p.position, p.velocity, p.mass, p.radius, half, duration)
    return pairs / (time.perf_counter() - start)


def step_mode_particle_steps(n: int, steps: int) -> dict[str, Any]:
    """W1s: the seed's step mode at dt = 0.01 s, all cores."""
    sim = packed_gas(n, collisions="step", dt=0.01)
    sim.run(steps=2)
    start = time.perf_counter()
    sim.run(steps=steps)
    seconds = time.perf_counter() - start
    return {
        "n": n,
        "steps": steps,
        "seconds": seconds,
        "per_second": n * steps / seconds,
        "threads": numba.get_num_threads(),
    }


def charged_gas(n: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Positions uniform in a square (density 0.25 per m^2) and alternating +1/-1 charges."""
    side = math.sqrt(n / 0.25)
    rng = np.random.default_rng(seed)
    position = rng.uniform(-side / 2, side / 2, (n, 2))
    charge = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    return position, charge


def _best_of(repeats: int, call: Any) -> float:
    call()
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - start)
    return best


def coulomb_costs(n: int, with_direct: bool, error_targets: int) -> dict[str, Any]:
    """W2: seconds per force evaluation, direct and tree, and the tree's RMS relative error
    against direct summation over ``error_targets`` particles (all of them when fewer). The
    direct sum is timed as a kick sums it, the forces alone, and with the energies and virials
    (an evaluation whose energies are read)."""
    position, charge = charged_gas(n)
    out: dict[str, Any] = {"n": n, "threads": numba.get_num_threads(), "theta": tree.THETA}
    force = np.empty((n, 2))
    energy, virial = np.empty(n), np.empty(n)
    repeats = max(1, min(20, int(2e6 / n)))
    buffers = tree.tree_buffers(n)

    def by_tree() -> None:
        tree.inverse_distance_tree(position, charge, 5.0, 0.0, force, energy, virial, buffers)

    out["tree_seconds"] = _best_of(repeats, by_tree)
    if with_direct:

        def direct() -> None:
            inverse_distance_direct(position, charge, 5.0, 0.0, 0.0, 0.0, False, force)

        def with_energies() -> None:
            inverse_distance_direct(
                position, charge, 5.0, 0.0, 0.0, 0.0, False, force, energy, virial
            )

        for name, sum_once in (("direct", direct), ("direct_with_energies", with_energies)):
            out[f"{name}_seconds"] = _best_of(max(1, repeats // 4), sum_once)
            out[f"{name}_pairs_per_second"] = n * (n - 1) / out[f"{name}_seconds"]
    by_tree()
    targets = np.random.default_rng(2).choice(n, size=min(n, error_targets), replace=False)
    exact = reference.inverse_distance_on(position, charge, 5.0, 0.0, targets)
    error = np.linalg.norm(force[targets] - exact, axis=1) / np.linalg.norm(exact, axis=1)
    out["tree_rms_relative_error"] = float(np.sqrt(np.mean(error**2)))
    return out


def charged_exact_costs(n: int, steps: int) -> list[dict[str, Any]]:
    """W4: the charged-gas preset with n disks in a box grown to keep its density, summed by
    tree, exact collisions, all cores: wall microseconds per particle-step over ``steps`` steps
    of dt = 0.01 s after a warm-up step, for each integrator; the queues built and refreshed
    per step (one per drift) and the largest relative energy drift, as `collidium run` measures
    it."""
    side = 20.0 * math.sqrt(n / 200)
    out = []
    for integrator in ("fixed", "adaptive"):
        sim = cd.load(
            "charged-gas",
            n=n,
            **{"vessel.width": side, "vessel.height": side, "forces.0.method": "tree",
               "run.integrator": integrator},
        )  # fmt: skip
        drift = EnergyDrift()  # as `collidium run` measures it, every step
        sim.observers.append(drift)
        sim.run(steps=1)
        built, refreshed = sim._drift.rebuilds, sim._drift.refreshes
        start = time.perf_counter()
        sim.run(steps=steps)
        seconds = time.perf_counter() - start
        out.append(
            {
                "n": n,
                "integrator": integrator,
                "threads": numba.get_num_threads(),
                "us_per_particle_step": seconds / (steps * n) * 1e6,
                "queues_per_step": (sim._drift.rebuilds - built) / steps,
                "refreshes_per_step": (sim._drift.refreshes - refreshed) / steps,
                "max_rel_drift": drift.max_rel_drift,
            }
        )
    return out


def kicked_few_costs(n: int, share: float, steps: int, rounds: int = 3) -> dict[str, Any]:
    """W4k: milliseconds per step (dt = 0.01 s, fixed integrator, all cores) of an n-disk gas at
    packing 0.3 whose first ``share`` of disks carry 1 C in a field of 1 N/C: with the queue kept
    across the kicks (the kicked disks predicted again), with it built afresh before each step,
    and without the field. Each way runs ``steps`` steps one call apiece, in ``rounds`` rounds
    alternated; the best round of each is kept."""
    gas = packed_gas(n, dt=0.01)
    p = gas.particles
    charge = np.zeros(n)
    charge[: int(share * n)] = 1.0
    ions = cd.Particles(p.position, p.velocity, radius=p.radius, mass=p.mass, charge=charge)
    field = [cd.UniformField(E=(1.0, 0.0))]
    kept = cd.Simulation(gas.container, ions, dt=0.01, forces=field, integrator="fixed")
    built = cd.Simulation(gas.container, ions.copy(), dt=0.01, forces=field, integrator="fixed")

    def steps_of(sim: cd.Simulation, afresh: bool = False) -> float:
        start = time.perf_counter()
        for _ in range(steps):
            if afresh:
                sim._drift.forget()  # the next drift builds the queue again
            sim.run(steps=1)
        return (time.perf_counter() - start) / steps * 1e3

    for sim in (kept, built, gas):
        sim.run(steps=2)  # compile, build the queue
    drift = kept._drift
    before = (drift.refreshes, drift.repredicted)
    best = {"kept": math.inf, "built": math.inf, "neutral": math.inf}
    for _ in range(rounds):
        best["kept"] = min(best["kept"], steps_of(kept))
        best["built"] = min(best["built"], steps_of(built, afresh=True))
        best["neutral"] = min(best["neutral"], steps_of(gas))
    taken = rounds * steps
    return {
        "n": n,
        "share": share,
        "threads": numba.get_num_threads(),
        "ms_per_step": best,
        "refreshes_per_step": (drift.refreshes - before[0]) / taken,
        "repredicted_per_step": (drift.repredicted - before[1]) / taken,
    }


def seed_scene_costs() -> list[dict[str, Any]]:
    """W3: every preset, wall seconds per simulated second over its own duration (capped), on a
    quiet machine and beside one CPU-bound process per core (`machine.busy_cores`)."""
    durations = {name: min(preset(name).run.time, 10.0) for name in PRESETS}
    for name, duration in durations.items():  # warm-up: every path a scene takes, compiled
        cd.load(name).run(time=min(duration, 1.0))
    quiet = {name: _scene_seconds(name, duration) for name, duration in durations.items()}
    with busy_cores() as cores:
        busy = {name: _scene_seconds(name, duration) for name, duration in durations.items()}
    return [
        {
            "scene": name,
            "n": cd.load(name).particles.n,
            "simulated_seconds": duration,
            "wall_seconds": quiet[name],
            "wall_per_simulated": quiet[name] / duration,
            "busy_cores": cores,
            "busy_wall_seconds": busy[name],
            "busy_speed_ratio": quiet[name] / busy[name],
        }
        for name, duration in durations.items()
    ]


def _scene_seconds(name: str, duration: float, least: float = 0.5) -> float:
    """Wall seconds of a fresh preset run for ``duration`` simulated seconds: the mean of as
    many runs as take ``least`` seconds in all (a run of a few milliseconds alone is at the
    mercy of the scheduler's time slices when other processes keep the cores busy)."""
    runs, wall = 0, 0.0
    while wall < least:
        sim = cd.load(name)
        start = time.perf_counter()
        sim.run(time=duration)
        wall += time.perf_counter() - start
        runs += 1
    return wall / runs


# VmHWM, not ru_maxrss: a child's ru_maxrss starts from its parent's at the fork. RssAnon and
# RssFile are read at the end of the run, where the resident size is at its peak.
_MEMORY_PROGRAM = """
import sys
sys.path.insert(0, {here!r})
from bench_core import packed_gas
sim = packed_gas({n}, dt=0.05)
sim.run(steps=3)
for line in open("/proc/self/status"):
    if line.startswith(("VmHWM:", "RssAnon:", "RssFile:")):
        print(line.split()[0][:-1], int(line.split()[1]) * 1024)
"""


def peak_memory(n: int) -> dict[str, int]:
    """Resident bytes of a fresh process that builds an N-disk gas and runs it exactly: the peak
    (``VmHWM``), and at the end of the run what it allocated (``RssAnon``) and the code and data
    of the files it mapped (``RssFile``: Python, NumPy, LLVM; shared with other processes)."""
    program = _MEMORY_PROGRAM.format(here=str(Path(__file__).parent), n=n)
    done = subprocess.run(
        [sys.executable, "-c", program], capture_output=True, text=True, check=True
    )
    return {key: int(value) for key, value in (line.split() for line in done.stdout.splitlines())}


def _measured(peer_run: dict[str, Any]) -> float | None:
    """A REBOUND gravity time per particle-step, if it was run (not predicted from a probe)."""
    return peer_run.get("us_per_particle_step") if peer_run.get("measured") else None


def _time_row(
    label: str, text: str, peer: str, ours: float, theirs: float | None
) -> tuple[str, str, str, str]:
    """A table row for a time per particle-step (lower is better) beside a peer's, if run."""
    if not theirs:
        return (label, text, "", "")
    return (label, text, f"{peer} {theirs:,.3g}", _ratio(theirs, ours))


def _ratio(ours: float, theirs: float | None) -> str:
    return f"{ours / theirs:,.1f}x" if theirs else ""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes, for a smoke test")
    parser.add_argument("--no-peers", action="store_true", help="skip REBOUND and pymunk")
    args = parser.parse_args()
    quick = args.quick
    have = {} if args.no_peers else peers.available()
    print(
        f"collidium {cd.__version__}, numba {numba.__version__}, {numba.get_num_threads()} "
        f"threads, {platform.machine()}; peers: {have}"
    )
    rows: list[tuple[str, str, str, str]] = []
    out: dict[str, Any] = {"numba": numba.__version__, "peers": have}

    sizes = [1_000, 10_000] if quick else [1_000, 10_000, 100_000, 1_000_000]
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    w1 = [exact_collisions_per_second(n, 2e5 if quick else 2e6) for n in sizes]
    numba.set_num_threads(threads)
    twin = numpy_twin_collisions_per_second(1_000, 0.2)
    out["w1_exact_gas"] = w1
    out["w1_numpy_twin_per_second"] = twin
    rebound_gas = {}
    if have.get("rebound"):
        for n in sizes[:3]:
            rebound_gas[n] = peers.rebound_hard_disks(n, PACKING, RADIUS)
    out["w1_rebound"] = list(rebound_gas.values())
    for row in w1:
        n = row["n"]
        peer_run = rebound_gas.get(n, {})
        # Only a settled gas (collision rate near Enskog's) gives REBOUND's real rate.
        theirs = peer_run.get("collisions_per_second") if peer_run.get("relaxed") else None
        peer = f"REBOUND {theirs:,.0f}" if theirs else ("NumPy twin" if n == 1_000 else "")
        ratio = _ratio(row["per_second"], theirs) if theirs else ""
        spread = f"{min(row['repeats']):,.3g}-{max(row['repeats']):,.3g}"
        rows.append(
            (
                f"W1 exact gas N={n:,} (1 core)",
                f"{row['per_second']:,.3g} coll/s (median; {spread})",
                peer,
                ratio,
            )
        )
    rows.append(
        (
            "W1 NumPy twin N=1,000",
            f"{twin:,.3g} coll/s",
            "",
            f"ours {w1[0]['per_second'] / twin:,.0f}x",
        )
    )

    step_sizes = [10_000, 100_000] if quick else [10_000, 100_000, 1_000_000]
    w1s = [step_mode_particle_steps(n, 20 if n >= 1e6 else 50) for n in step_sizes]
    out["w1_step_mode"] = w1s
    munk = {}
    if have.get("pymunk"):
        for n in step_sizes:
            munk[n] = peers.pymunk_balls(n, PACKING, RADIUS, dt=0.01)
    out["w1_pymunk"] = list(munk.values())
    for row in w1s:
        theirs = munk.get(row["n"], {}).get("particle_steps_per_second")
        rows.append(
            (
                f"W1s step mode N={row['n']:,} ({row['threads']} thr)",
                f"{row['per_second']:,.3g} p-steps/s",
                f"pymunk {theirs:,.3g}" if theirs else "",
                _ratio(row["per_second"], theirs),
            )
        )

    charged = [200, 1_000, 10_000] if quick else [200, 1_000, 5_000, 10_000, 100_000, 1_000_000]
    w2 = [coulomb_costs(n, with_direct=n <= 100_000, error_targets=1000) for n in charged]
    out["w2_coulomb"] = w2
    out["w2_auto_crossover"] = TREE_CROSSOVER
    gravity: dict[tuple[int, str], dict[str, Any]] = {}
    if have.get("rebound"):
        for n in charged:
            if n <= 10_000:
                gravity[(n, "basic")] = peers.rebound_gravity(n, method="basic")
            if n <= 100_000 or not quick:
                gravity[(n, "tree")] = peers.rebound_gravity(n, method="tree")
    out["w2_rebound"] = [dict(v, method=k[1]) for k, v in gravity.items()]
    for row in w2:
        n = row["n"]
        if "direct_seconds" in row:
            ours = row["direct_seconds"] / n * 1e6
            theirs = _measured(gravity.get((n, "basic"), {}))
            rows.append(
                _time_row(
                    f"W2 direct N={n:,} ({row['threads']} thr)",
                    f"{ours:,.3g} us/p-step; {row['direct_pairs_per_second']:,.3g} pairs/s "
                    f"({row['direct_with_energies_pairs_per_second']:,.3g} with energies)",
                    "REBOUND basic",
                    ours,
                    theirs,
                )
            )
        ours = row["tree_seconds"] / n * 1e6
        theirs = _measured(gravity.get((n, "tree"), {}))
        rows.append(
            _time_row(
                f"W2 tree N={n:,} (theta {row['theta']})",
                f"{ours:,.3g} us/p-step; err {row['tree_rms_relative_error']:.1e}",
                "REBOUND tree",
                ours,
                theirs,
            )
        )

    w4_sizes = [10_000] if quick else [10_000, 100_000]
    w4 = [row for n in w4_sizes for row in charged_exact_costs(n, 5 if n > 10_000 else 20)]
    out["w4_charged_exact"] = w4
    for row in w4:
        rows.append(
            (
                f"W4 charged gas N={row['n']:,} {row['integrator']} ({row['threads']} thr)",
                f"{row['us_per_particle_step']:.3g} us/p-step, "
                f"{row['queues_per_step']:.3g} built, {row['refreshes_per_step']:.3g} "
                "refreshed/step",
                "",
                f"drift {row['max_rel_drift']:.1e}",
            )
        )

    w4k = kicked_few_costs(10_000 if quick else 100_000, 0.01, 20 if quick else 50)
    out["w4k_kicked_few"] = w4k
    ms = w4k["ms_per_step"]
    rows.append(
        (
            f"W4k gas N={w4k['n']:,}, 1% ions in a field ({w4k['threads']} thr)",
            f"{ms['kept']:.3g} ms/step, {w4k['repredicted_per_step']:,.0f} predicted again",
            f"built afresh {ms['built']:.3g}; no field {ms['neutral']:.3g}",
            f"{ms['built'] / ms['kept']:.2f}x faster",
        )
    )

    w3 = seed_scene_costs()
    out["w3_seed_scenes"] = w3
    for row in w3:
        rows.append(
            (
                f"W3 {row['scene']} (N={row['n']})",
                f"{row['wall_per_simulated']:.3g} wall s / sim s "
                f"({1.0 / row['wall_per_simulated']:,.0f}x real time)",
                f"busy: {row['busy_wall_seconds'] / row['simulated_seconds']:.3g}",
                f"busy/quiet speed {row['busy_speed_ratio']:.2f}",
            )
        )

    big_n = 100_000 if quick else 1_000_000
    small, large = peak_memory(1_000), peak_memory(big_n)
    per_particle = (large["VmHWM"] - small["VmHWM"]) / (big_n - 1_000)
    out["memory"] = {"n1000": small, f"n{big_n}": large, "bytes_per_particle": per_particle}
    mib = 2**20
    rows.append(
        (
            f"M peak RSS exact run N={big_n:,}",
            f"{large['VmHWM'] / 1e6:,.0f} MB = {large['VmHWM'] / mib:,.0f} MiB "
            f"(anon {large['RssAnon'] / mib:,.0f}, files {large['RssFile'] / mib:,.0f})",
            f"N=1,000: {small['VmHWM'] / mib:,.0f} MiB",
            f"{per_particle:,.0f} B/particle",
        )
    )

    print(f"{'workload':<40} {'collidium':>40} {'peer':>26} {'ratio':>14}")
    for label, ours_text, peer_text, ratio_text in rows:
        print(f"{label:<40} {ours_text:>40} {peer_text:>26} {ratio_text:>14}")
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "core.json").write_text(json.dumps(out, indent=2, default=float))


if __name__ == "__main__":
    main()
