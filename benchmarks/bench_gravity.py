"""Newton's gravity beside REBOUND: one full leapfrog step of N point masses, direct and by tree.

Run: ``python benchmarks/bench_gravity.py [--sizes 10000 100000] [--threads 2]``. Prints a table
and writes ``benchmarks/results/gravity.json``.

Both codes take the same job (`peers.rebound_gravity`): N masses of 1/N kg at rest, uniform in
a centred square of side sqrt(N) m, G = 1, Plummer softening 0.01 m, dt = 1e-3 s, fixed-step
leapfrog (kick, drift, force, kick). collidium runs `Newton` through a `Simulation` (collisions
off, ``integrator="fixed"``, a walled box around the square), so its figure includes what a run
pays besides the force. The trees are set to the same accuracy: an RMS relative force error of
about 1e-3 (ours at its default opening angle, REBOUND's at `peers.rebound_theta_1e3`), measured
on the same particles against the exact direct sum. Every timing follows a warm-up step.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numba
import numpy as np

import collidium as cd
from collidium.forces import ForceField

sys.path.insert(0, str(Path(__file__).parent))
import peers

RESULTS = Path(__file__).parent / "results"
SOFTENING = 0.01


def newton_step(n: int, method: str, max_seconds: float = 10.0, seed: int = 1) -> dict[str, Any]:
    """Seconds per full step of collidium's `Newton` (``method`` "direct" or "tree"), and for
    the tree its RMS relative force error on `peers._error_samples` particles."""
    position = peers._uniform_square(n, seed)
    side = 1.1 * math.sqrt(n)
    particles = cd.Particles(position, mass=1.0 / n, radius=0.0)
    force = cd.Newton(G=1.0, softening=SOFTENING, method=method)  # type: ignore[arg-type]
    box = cd.Box(side, side)
    out: dict[str, Any] = {"n": n, "method": method, "threads": numba.get_num_threads()}
    if method == "tree":
        acceleration = ForceField((force,)).evaluate(particles, box)
        m = peers._error_samples(n)
        index = np.sort(np.random.default_rng(seed + 1).choice(n, m, replace=False))
        exact = peers.direct_accelerations(position, 1.0 / n, index, SOFTENING)
        out["force_error_rms"] = peers._rms_relative_error(acceleration[index], exact)
        out["theta"] = force.theta
    sim = cd.Simulation(box, particles, forces=[force], dt=1e-3, collisions="off",
                        integrator="fixed")  # fmt: skip
    start = time.perf_counter()
    sim.run(steps=1)  # warm-up: compile, first force evaluation
    warm = time.perf_counter() - start
    steps = int(min(200, max(1, max_seconds / max(warm, 1e-9))))
    start = time.perf_counter()
    sim.run(steps=steps)
    seconds = (time.perf_counter() - start) / steps
    return out | {"steps": steps, "seconds_per_step": seconds,
                  "us_per_particle_step": 1e6 * seconds / n}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--threads", type=int, default=None, help="numba threads (default all)")
    args = parser.parse_args()
    if args.threads:
        numba.set_num_threads(args.threads)
    have = peers.available()
    rows, out = [], {"ours": [], "rebound": [], "versions": have}
    for n in args.sizes:
        for method, theirs_method in (("direct", "basic"), ("tree", "tree")):
            ours = newton_step(n, method)
            out["ours"].append(ours)
            theirs: dict[str, Any] = {}
            if have.get("rebound"):
                theirs = peers.rebound_gravity(n, method=theirs_method, softening=SOFTENING)
                out["rebound"].append(theirs)
            rows.append((n, method, ours, theirs))
    print(f"{'N':>8} {'method':>7} {'ours us/p-step':>15} {'REBOUND':>10} {'ratio':>7}  errors")
    for n, method, ours, theirs in rows:
        mine = ours["us_per_particle_step"]
        peer = theirs.get("us_per_particle_step")
        measured = "" if theirs.get("measured", True) else " (predicted)"
        ratio = f"{peer / mine:.2f}x" if peer else ""
        error = (f"{ours['force_error_rms']:.1e} vs {theirs.get('force_error_rms', math.nan):.1e}"
                 if method == "tree" else "")  # fmt: skip
        print(
            f"{n:>8,} {method:>7} {mine:>15.3g} {peer or math.nan:>10.3g}{measured} {ratio:>7}"
            f"  {error}"
        )
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "gravity.json").write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
