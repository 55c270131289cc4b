"""Compile the kernels every preset runs into numba's cache: ``python -m collidium.precompile``.

pip runs this when it builds collidium's wheel (``hatch_build.py``), so that the wheel carries
the compiled kernels and the first run after installing loads them instead of compiling them
for half a minute. Run it by hand to fill a cache of your own, such as a ``NUMBA_CACHE_DIR``
that a cluster's workers share before a sweep. Given preset names, it compiles for those alone.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

from collidium.presets import PRESETS, preset
from collidium.runner import execute, prepare

#: Steps each preset runs: enough for the compiled flights between the summary's readings.
STEPS = 20
#: The gas with so many disks that the passes over all of them run in parallel chunks, kernels
#: of their own (from `collidium.kernels.audit.PARALLEL_FROM`): as the viewer's large gases.
LARGE_GAS = "large-gas"
_LARGE_GAS_PARAMETERS = {"n": 20_000, "width": 350.0, "height": 350.0}


def precompile(names: list[str], steps: int = STEPS) -> None:
    """Run each preset in ``names`` (or `LARGE_GAS`) for ``steps`` steps, as ``collidium run``
    does, so that numba compiles and caches every kernel they call."""
    for name in names:
        spec = preset("gas", **_LARGE_GAS_PARAMETERS) if name == LARGE_GAS else preset(name)
        sim, job = prepare(spec, steps=steps)
        execute(sim, job)


def groups(workers: int) -> list[list[str]]:
    """Every preset and `LARGE_GAS` in ``workers`` groups (at most two: the neutral ones, whose
    kernels are the exact engine's, and those under forces), to compile side by side."""
    forced = {name: bool(preset(name).forces) for name in PRESETS} | {LARGE_GAS: False}
    if workers < 2:
        return [list(forced)]
    return [[name for name in forced if forced[name] == group] for group in (False, True)]


def main(argv: list[str] | None = None) -> int:
    """Precompile the presets named (in this process), or every preset in a process per group
    (`groups`), saying how long it took."""
    names = sys.argv[1:] if argv is None else argv
    if {"-h", "--help"} & set(names):
        sys.stdout.write(f"{__doc__}\nusage: python -m collidium.precompile [PRESET ...]\n")
        return 0
    known = [*PRESETS, LARGE_GAS]
    if unknown := [name for name in names if name not in known]:
        sys.stderr.write(f"collidium: preset: unknown preset {unknown[0]!r}; choose from "
                         f"{', '.join(known)}\n")  # fmt: skip
        return 2
    if names:
        precompile(names)
        return 0
    start = time.perf_counter()
    command = [sys.executable, "-m", "collidium.precompile"]
    workers = [subprocess.Popen(command + group) for group in groups(os.cpu_count() or 1)]
    failed = [worker.args for worker in workers if worker.wait() != 0]
    if failed:
        sys.stderr.write(f"collidium: precompiling failed: {failed}\n")
        return 1
    sys.stderr.write(f"collidium: kernels compiled in {time.perf_counter() - start:.0f} s\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
