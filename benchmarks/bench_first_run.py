"""The first run on a fresh machine. Run: ``python benchmarks/bench_first_run.py [--scene gas]``.

F1  ``collidium run <scene> --time 1 --verbose`` in a subprocess on an empty numba cache (every
    kernel it uses compiles), then again on the cache that run left (every kernel loads): wall
    seconds of each, seconds until it says it is running (its first line, once the scene is
    built: the start), and how many kernels each compiled (numba's dispatcher statistics,
    helpers inlined into a kernel counted too; 0 on the second run). The targets: the first
    within 8 s, the second starting within 1 s.
F2  The same first run as a new user makes it: the wheel built from this clone (``pip wheel``,
    which compiles the presets' kernels into it: ``hatch_build.py``), installed into a fresh
    virtual environment, then ``collidium run <scene>`` there on numba's cache as installed:
    seconds to build the wheel, to install it, and of the run, with the kernels it compiled.
    ``--no-wheel`` leaves it out (it takes a few minutes).

Prints a table and writes ``benchmarks/results/first_run.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

RESULTS = Path(__file__).parent / "results"

#: Runs the command line as the ``collidium`` program does, counting the kernels numba compiled
#: before it exits.
PROBE = """
import gc, sys
import numba.core.registry
import collidium.cli as cli
main = cli.main
def counted():
    code = main()
    compiled = sum(sum(obj.stats.cache_misses.values()) for obj in gc.get_objects()
                   if isinstance(obj, numba.core.registry.CPUDispatcher))
    print(f"COMPILED {compiled}", file=sys.stderr)
    return code
cli.main = counted
sys.exit(cli.console())
"""


def timed_run(scene: str, cache: str | None, python: str = sys.executable) -> dict[str, float]:
    """Wall seconds of one run of ``scene`` by ``python`` with numba's cache in ``cache`` (None:
    where numba puts it, next to the installed sources), seconds until its first line
    (``running ...``), and the number of kernels it compiled."""
    environment = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    if cache is not None:
        environment["NUMBA_CACHE_DIR"] = cache
    start = time.perf_counter()
    command = [python, "-c", PROBE, "run", scene, "--time", "1", "--verbose"]
    with subprocess.Popen(command, env=environment, stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True) as process:  # fmt: skip
        assert process.stderr is not None
        lines: list[str] = []
        started = None
        for line in process.stderr:
            if started is None and line.startswith("running "):
                started = time.perf_counter() - start
            lines.append(line)
    wall = time.perf_counter() - start
    if process.returncode != 0 or started is None:
        raise RuntimeError("".join(lines))
    compiled = next(x for x in lines if x.startswith("COMPILED"))
    return {"wall_s": wall, "start_s": started, "compiled": int(compiled.split()[1])}


def installed_run(scene: str) -> dict[str, float]:
    """F2: seconds to build this clone's wheel (from a copy without what earlier builds left:
    ``build/kernels/`` would spare it the compiling) and to install it into a fresh virtual
    environment, and the first run there (`timed_run`)."""
    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as folder:
        wheels, venv, source = (Path(folder) / name for name in ("wheels", "venv", "source"))
        left = shutil.ignore_patterns(".git", "build", "node_modules", "__pycache__", ".lowest")
        shutil.copytree(root, source, ignore=left)
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", wheels,
                        source], check=True)  # fmt: skip
        built = time.perf_counter()
        subprocess.run([sys.executable, "-m", "venv", venv], check=True)
        python = str(venv / "bin" / "python")
        wheel = next(wheels.glob("collidium-*.whl"))
        subprocess.run([python, "-m", "pip", "install", "-q", wheel], check=True)
        installed = time.perf_counter()
        run = timed_run(scene, None, python)
        shutil.rmtree(venv)
    return {"wheel_s": built - start, "install_s": installed - built} | run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="gas", help="preset or scenario file (default: gas)")
    parser.add_argument("--no-wheel", action="store_true", help="leave out F2")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as cache:
        cold = timed_run(args.scene, cache)
        warm = timed_run(args.scene, cache)
    print(f"F1  {args.scene}: first run {cold['wall_s']:.1f} s ({cold['compiled']} kernels "
          f"compiled; target 8 s), second {warm['wall_s']:.2f} s, running after "
          f"{warm['start_s']:.2f} s ({warm['compiled']} compiled; target 1 s)")  # fmt: skip
    out = {"scene": args.scene, "cold": cold, "warm": warm}
    if not args.no_wheel:
        out["installed"] = new = installed_run(args.scene)
        print(f"F2  {args.scene}: wheel built in {new['wheel_s']:.0f} s, installed in "
              f"{new['install_s']:.0f} s; first run there {new['wall_s']:.1f} s "
              f"({new['compiled']} kernels compiled)")  # fmt: skip
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "first_run.json").write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
