"""Serial or parallel: where a kernel's rows are worth the second thread, quiet and on a busy
machine.

Run: ``python benchmarks/bench_threads.py [--sizes 2 8 32 64 128 256 1024] [--repeats 5]``.
Prints a table and writes ``benchmarks/results/threads.json``.

T1  the direct inverse-distance sum (`collidium.kernels.pairwise`): microseconds per call (the
    median of the repeats) on the calling thread (`direct_serial`) and on all threads
    (`direct_parallel`), for N charges, first on a quiet machine, then beside one CPU-bound
    process per core, which this script starts and stops. Both give the same bits;
    `inverse_distance_direct` switches at ``PARALLEL_DIRECT_FROM``.
T2  the same for the adaptive substeps' stiffness (`stiffness_serial`, `stiffness_parallel`).
T3  what numba's idle OpenMP threads cost: 300 steps of a 1e5-disk gas at packing 0.1 (the
    viewer's), wall seconds and the CPU seconds of the whole process, with collidium's spin
    count (`collidium.kernels.OPENMP_SPINS`) and with GNU OpenMP's default (300,000), each in a
    process of its own (the count is read when the threads start), alternated ``--rounds``
    times.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba
import numpy as np

from collidium.kernels import OPENMP_SPINS, pairwise

sys.path.insert(0, str(Path(__file__).parent))
from machine import busy_cores

RESULTS = Path(__file__).parent / "results"


def median_microseconds(call: Callable[[], None], repeats: int, budget: float = 0.2) -> float:
    """The median of ``repeats`` averages over as many calls as fit about ``budget`` seconds (a
    median, not the best: on a busy machine the stalls are what is measured)."""
    call()
    start = time.perf_counter()
    call()
    calls = max(1, int(budget / max(time.perf_counter() - start, 1e-7)))
    averages = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(calls):
            call()
        averages.append((time.perf_counter() - start) / calls)
    return float(np.median(averages)) * 1e6


def kernel_rows(n: int, repeats: int) -> list[dict[str, Any]]:
    """T1 and T2 at one size: each kernel's serial and parallel rows on the same charges."""
    rng = np.random.default_rng(1)
    position = rng.uniform(-10.0, 10.0, (n, 2))
    velocity = rng.normal(0.0, 1.0, (n, 2))
    charge = rng.choice([-1.0, 1.0], n)
    mass = np.ones(n)
    force, energy, virial = np.empty((n, 2)), np.empty(n), np.empty(n)
    direct = (position, charge, 1.0, 0.01, 20.0, 20.0, False, force, energy, virial, True)
    stiffness = (position, velocity, charge, mass, 1.0, 0.01, 20.0, 20.0, False)
    rows = []
    for name, serial, parallel, args in (
        ("T1 direct sum", pairwise.direct_serial, pairwise.direct_parallel, direct),
        ("T2 stiffness", pairwise.stiffness_serial, pairwise.stiffness_parallel, stiffness),
    ):
        rows.append(
            {
                "kernel": name,
                "n": n,
                "serial_us": median_microseconds(lambda s=serial, a=args: s(*a), repeats),
                "parallel_us": median_microseconds(lambda p=parallel, a=args: p(*a), repeats),
            }
        )
    return rows


#: T3's child: the viewer's gas (`bench_viewer.gas`), a warm-up, then wall and CPU seconds (all
#: threads) of the steps.
_SPIN_CHILD = f"""
import sys, time
sys.path.insert(0, {str(Path(__file__).parent)!r})
from bench_viewer import gas
sim = gas(100_000).sim
sim.run(steps=5)
wall, cpu = time.perf_counter(), time.process_time()
sim.run(steps=300)
print(time.perf_counter() - wall, time.process_time() - cpu)
"""

#: GNU OpenMP's own spin count, when the environment sets none.
GNU_DEFAULT_SPINS = 300_000


def idle_spin_rows(rounds: int) -> list[dict[str, Any]]:
    """T3: wall and CPU seconds of the gas's steps with each spin count, alternated."""
    rows = []
    for _ in range(rounds):
        for spins in (OPENMP_SPINS, GNU_DEFAULT_SPINS):
            env = os.environ | {"GOMP_SPINCOUNT": str(spins)}
            out = subprocess.run([sys.executable, "-c", _SPIN_CHILD], env=env, check=True,
                                 capture_output=True, text=True).stdout  # fmt: skip
            wall, cpu = (float(x) for x in out.split())
            rows.append({"spins": spins, "wall_s": wall, "cpu_s": cpu})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[2, 32, 128, 256, 512, 1024])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--rounds", type=int, default=3, help="T3's alternated rounds")
    args = parser.parse_args()
    rows: list[dict[str, Any]] = []
    rows += [row | {"load": "quiet"} for n in args.sizes for row in kernel_rows(n, args.repeats)]
    with busy_cores() as cores:
        rows += [row | {"load": "busy"} for n in args.sizes for row in kernel_rows(n, args.repeats)]
    print(
        f"{numba.get_num_threads()} threads; busy: beside {cores} CPU-bound processes; the "
        f"kernels go parallel from N = {pairwise.PARALLEL_DIRECT_FROM}"
    )
    print(f"{'':<16}{'load':>6}{'N':>7}{'serial us':>12}{'parallel us':>13}{'par/ser':>9}")
    for row in sorted(rows, key=lambda r: (r["kernel"], r["load"] == "busy", r["n"])):
        ratio = row["parallel_us"] / row["serial_us"]
        print(f"{row['kernel']:<16}{row['load']:>6}{row['n']:>7}{row['serial_us']:>12.1f}"
              f"{row['parallel_us']:>13.1f}{ratio:>9.2f}")  # fmt: skip
    spins = idle_spin_rows(args.rounds)
    print(f"\nT3 300 steps of a 1e5-disk gas: {'spins':>9}{'wall s':>9}{'CPU s':>8}")
    for row in spins:
        print(f"{'':<35}{row['spins']:>9}{row['wall_s']:>9.2f}{row['cpu_s']:>8.2f}")
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "threads.json").write_text(json.dumps(rows + spins, indent=1) + "\n")


if __name__ == "__main__":
    main()
