"""Core benchmarks (issue: core simulator). Run: ``python benchmarks/bench_core.py [--quick]``.

W1  exact hard-disk gas at packing fraction 0.3: pair collisions per second (one core), N = 1e3,
    1e4, 1e5, beside the all-pairs NumPy twin at the smallest N.
W2  charged gas, N = 2000: Coulomb pair interactions per second (numba direct sum on all cores),
    beside the NumPy twin.
W3  pool-break, 60 simulated seconds: wall-clock seconds.

Prints a table and writes ``benchmarks/results/core.json``. Timings are taken after a warm-up run
so that compilation is not counted.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import time
from pathlib import Path

import numba
import numpy as np

import collidium as cd
from collidium.initial import random_positions
from collidium.kernels import reference
from collidium.kernels.pairwise import coulomb_direct

RESULTS = Path(__file__).parent / "results"


def packed_gas(n: int, packing: float = 0.3, radius: float = 0.25, seed: int = 1) -> cd.Simulation:
    """N disks at the given packing fraction in a square reflecting box, speeds ~ 1 m/s."""
    side = math.sqrt(n * math.pi * radius**2 / packing)
    rng = np.random.default_rng(seed)
    position = random_positions(n, np.full(n, radius), side, side, rng)
    velocity = rng.normal(0.0, 1.0, (n, 2))
    return cd.Simulation(
        cd.Box(side, side), cd.Particles(position, velocity, radius=radius), dt=1.0
    )


def collisions_per_second(n: int, target: int) -> dict[str, float]:
    """W1: time the exact engine until about ``target`` pair collisions."""
    sim = packed_gas(n)
    sim.run(steps=1)  # warm-up, compile, relax the lattice-free start
    rate_estimate = max(sim.counters.pair_collisions, 1) / sim.dt
    sim.dt = max(target / rate_estimate, 1e-3)
    before = sim.counters.pair_collisions
    start = time.perf_counter()
    sim.run(steps=1)
    seconds = time.perf_counter() - start
    done = sim.counters.pair_collisions - before
    return {"n": n, "collisions": done, "seconds": seconds, "per_second": done / seconds}


def reference_collisions_per_second(n: int, duration: float) -> float:
    """W1 peer: the NumPy twin (all pairs at every event) on the same kind of gas."""
    sim = packed_gas(n)
    p = sim.particles
    position, velocity = p.position.copy(), p.velocity.copy()
    half = 0.5 * sim.container.size
    start = time.perf_counter()
    pairs, *_ = reference.event_drift(position, velocity, p.mass, p.radius, half, duration)
    return pairs / (time.perf_counter() - start)


def pair_interactions_per_second(n: int, repeats: int) -> dict[str, float]:
    """W2: Coulomb direct sum, N (N - 1) pair terms per evaluation, numba and NumPy."""
    sim = cd.load("charged-gas", n=n, width=200.0, height=200.0)
    p = sim.particles
    force, energy, virial = np.empty((n, 2)), np.empty(n), np.empty(n)

    def kernel() -> None:
        coulomb_direct(p.position, p.charge, 5.0, 0.0, 0.0, 0.0, False, force, energy, virial)

    kernel()
    start = time.perf_counter()
    for _ in range(repeats):
        kernel()
    per_eval = (time.perf_counter() - start) / repeats
    start = time.perf_counter()
    reference.coulomb_direct(p.position, p.charge, 5.0, 0.0)
    per_eval_numpy = time.perf_counter() - start
    pairs = n * (n - 1)
    return {
        "n": n,
        "threads": numba.get_num_threads(),
        "per_second": pairs / per_eval,
        "numpy_per_second": pairs / per_eval_numpy,
    }


def pool_break_seconds(simulated: float) -> dict[str, float]:
    """W3: wall seconds for the pool-break preset (exact collisions, dt = 0.01 s reports)."""
    cd.load("pool-break").run(time=0.1)  # warm-up
    sim = cd.load("pool-break")
    start = time.perf_counter()
    sim.run(time=simulated)
    seconds = time.perf_counter() - start
    return {
        "simulated_seconds": simulated,
        "wall_seconds": seconds,
        "collisions": sim.counters.pair_collisions,
        "escaped": sim.escaped(),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes, for a smoke test")
    args = parser.parse_args()
    sizes = [1_000, 10_000] if args.quick else [1_000, 10_000, 100_000]
    target = 50_000 if args.quick else 1_000_000

    w1 = [collisions_per_second(n, target) for n in sizes]
    numpy_rate = reference_collisions_per_second(1_000, 0.2)
    w2 = pair_interactions_per_second(2_000, 5 if args.quick else 50)
    w3 = pool_break_seconds(6.0 if args.quick else 60.0)

    print(f"collidium {cd.__version__}, numba {numba.__version__}, {platform.processor() or ''}")
    print(f"{'workload':<40}{'figure':>16}{'vs NumPy twin':>16}")
    for row in w1:
        ratio = f"{row['per_second'] / numpy_rate:,.0f}x" if row["n"] == 1_000 else ""
        label = f"W1 exact gas N={row['n']:,} coll/s"
        print(f"{label:<40}{row['per_second']:>16,.0f}{ratio:>16}")
    print(f"{'W1 NumPy twin N=1,000 coll/s':<40}{numpy_rate:>16,.0f}")
    label = f"W2 Coulomb N={w2['n']:,} pairs/s ({w2['threads']} thr)"
    ratio = f"{w2['per_second'] / w2['numpy_per_second']:,.1f}x"
    print(f"{label:<40}{w2['per_second']:>16,.3g}{ratio:>16}")
    label = f"W3 pool-break {w3['simulated_seconds']:g} s simulated, wall s"
    print(f"{label:<40}{w3['wall_seconds']:>16.2f}")

    RESULTS.mkdir(exist_ok=True)
    out = {"w1_exact_gas": w1, "w1_numpy_twin_per_second": numpy_rate, "w2_coulomb": w2,
           "w3_pool_break": w3, "numba": numba.__version__}  # fmt: skip
    (RESULTS / "core.json").write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
