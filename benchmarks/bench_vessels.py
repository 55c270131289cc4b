"""Vessels. Run: ``python benchmarks/bench_vessels.py [--quick] [--rounds 4]``.

V1  the exact hard-disk gas at packing 0.3 (one thread), N = 1e5, in a box and in a circle of the
    same area: pair collisions per second, and the circle's rate over the box's. The shapes are
    measured in alternating rounds in the same run (the machine may be shared), so the ratio is
    given per round as well as its range.

Prints a table and writes ``benchmarks/results/vessels.json``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numba

import collidium as cd

sys.path.insert(0, str(Path(__file__).parent))
from bench_core import PACKING, RADIUS, exact_collisions_per_second

RESULTS = Path(__file__).parent / "results"


def vessels_of_area(n: int) -> dict[str, cd.vessels.Vessel]:
    """A square box and a circle, each of the area that holds ``n`` disks at `PACKING`."""
    area = n * math.pi * RADIUS**2 / PACKING
    return {
        "box": cd.Box(math.sqrt(area), math.sqrt(area)),
        "circle": cd.Circle(math.sqrt(area / math.pi)),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="N = 1e4, for a smoke test")
    parser.add_argument("--rounds", type=int, default=4, help="alternating rounds of the shapes")
    args = parser.parse_args()
    n = 10_000 if args.quick else 100_000
    numba.set_num_threads(1)
    shapes = vessels_of_area(n)
    rounds = []
    for k in range(args.rounds):
        rates = {name: exact_collisions_per_second(n, 2e5 if args.quick else 2e6, 1, vessel)
                 ["per_second"] for name, vessel in shapes.items()}  # fmt: skip
        rates["circle_over_box"] = rates["circle"] / rates["box"]
        rounds.append(rates)
        print(f"round {k + 1}: box {rates['box']:.3g}/s, circle {rates['circle']:.3g}/s, "
              f"ratio {rates['circle_over_box']:.2f}")  # fmt: skip
    ratios = [r["circle_over_box"] for r in rounds]
    print(f"V1 N = {n}: circle / box = {min(ratios):.2f} .. {max(ratios):.2f}")
    RESULTS.mkdir(exist_ok=True)
    out = {"n": n, "packing": PACKING, "rounds": rounds, "ratio_range": [min(ratios), max(ratios)]}
    (RESULTS / "vessels.json").write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
