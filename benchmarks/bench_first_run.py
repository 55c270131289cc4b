"""The first run on a fresh machine. Run: ``python benchmarks/bench_first_run.py [--scene gas]``.

F1  ``collidium run <scene> --time 1 -q`` in a subprocess on an empty numba cache (every kernel
    it uses compiles), then again on the cache that run left (every kernel loads): wall seconds of
    each, and how many kernels each compiled (numba's dispatcher statistics, helpers inlined into
    a kernel counted too; 0 on the second run). The targets: the first within 8 s, the second
    within 1 s.

Prints a table and writes ``benchmarks/results/first_run.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

RESULTS = Path(__file__).parent / "results"

#: Runs the command line in-process, then counts the kernels numba compiled.
PROBE = """
import gc, sys
import numba.core.registry
from collidium.cli import main
code = main(sys.argv[1:])
compiled = sum(sum(obj.stats.cache_misses.values()) for obj in gc.get_objects()
               if isinstance(obj, numba.core.registry.CPUDispatcher))
print(f"COMPILED {compiled}", file=sys.stderr)
sys.exit(code)
"""


def timed_run(scene: str, cache: str) -> dict[str, float]:
    """Wall seconds of one quiet run of ``scene`` with numba's cache in ``cache``, and the
    number of kernels it compiled."""
    environment = os.environ | {"NUMBA_CACHE_DIR": cache}
    start = time.perf_counter()
    result = subprocess.run(
        [sys.executable, "-c", PROBE, "run", scene, "--time", "1", "-q"],
        env=environment, capture_output=True, text=True, check=True,
    )  # fmt: skip
    wall = time.perf_counter() - start
    line = next(x for x in result.stderr.splitlines() if x.startswith("COMPILED"))
    return {"wall_s": wall, "compiled": int(line.split()[1])}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="gas", help="preset or scenario file (default: gas)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as cache:
        cold = timed_run(args.scene, cache)
        warm = timed_run(args.scene, cache)
    print(f"F1  {args.scene}: first run {cold['wall_s']:.1f} s ({cold['compiled']} kernels "
          f"compiled; target 8 s), second {warm['wall_s']:.2f} s ({warm['compiled']} compiled; "
          "target 1 s)")  # fmt: skip
    RESULTS.mkdir(exist_ok=True)
    out = {"scene": args.scene, "cold": cold, "warm": warm}
    (RESULTS / "first_run.json").write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
