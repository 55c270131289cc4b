"""W1 of two revisions at once: a comparison that a shared, noisy machine cannot tilt.

Run: ``python benchmarks/bench_paired.py REV_A REV_B [--n 1e6] [--rounds 4] [--repeats 5]``
(git revisions of this repository; ``WORKTREE`` is the working copy as it is, uncommitted
changes too). Prints each round and the ratio B / A of each; writes nothing.

Runs of one revision after the other, as the other benchmarks alternate them, see the machine
change between them: on a machine shared with other programs, W1 at 1e6 disks varied by a third
from one run to the next. Here each round runs both at once, each in a process of its own pinned
to a core of its own (the two swap cores and start order from round to round), so that whatever
else loads the machine loads both alike; the ratio within a round is what is compared. The two
also share the cache and memory between them, alike. Each revision is checked out into a
temporary git worktree, with a numba cache of its own filled before the first round, and runs
W1 (`bench_core.exact_collisions_per_second`, one thread) of this checkout's ``bench_core.py``;
both wait after the warm-up, and time together.

What it cannot tell apart: a revision against itself (``HEAD WORKTREE`` with changes to
benchmarks alone) gave B/A of 0.948-1.067 by round at 1e6 disks (four rounds), so a change is
worth keeping when its rounds stay clear of that band, not when one round is.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
WORKTREE = "WORKTREE"

#: What each process runs: W1 pinned to one core. Warmed up, it says so and waits for a line
#: (both then time at once), and prints its rate (collisions/s) last.
_DRIVER = """
import os, sys
os.sched_setaffinity(0, {{{core}}})
sys.path.insert(0, {benchmarks!r})
import numba
numba.set_num_threads(1)
import bench_core
def warmed():
    print("warmed", flush=True)
    sys.stdin.readline()
print(bench_core.exact_collisions_per_second({n}, {target}, {repeats}, None, warmed)["per_second"])
"""


def checkout(revision: str, into: Path) -> Path:
    """The ``src`` folder of ``revision`` checked out into ``into`` (the working copy's own for
    `WORKTREE`)."""
    if revision == WORKTREE:
        return ROOT / "src"
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(into),
                    revision], check=True)  # fmt: skip
    return into / "src"


def start(source: Path, cache: Path, core: int, n: int, repeats: int) -> subprocess.Popen[str]:
    """A process running W1 of the package in ``source`` on ``core``."""
    code = _DRIVER.format(core=core, benchmarks=str(ROOT / "benchmarks"), n=n, target=2e6,
                          repeats=repeats)  # fmt: skip
    env = {**os.environ, "PYTHONPATH": str(source), "NUMBA_CACHE_DIR": str(cache)}
    return subprocess.Popen([sys.executable, "-c", code], env=env, stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)  # fmt: skip


def warmed(process: subprocess.Popen[str]) -> None:
    """Wait until a process of `start` has warmed up."""
    assert process.stdout is not None
    if process.stdout.readline().strip() != "warmed":
        raise SystemExit(f"bench_paired: a W1 run failed (exit {process.wait()})")


def release(process: subprocess.Popen[str]) -> None:
    """Let a process of `start`, warmed up, time W1."""
    assert process.stdin is not None
    process.stdin.write("go\n")
    process.stdin.flush()


def rate(process: subprocess.Popen[str]) -> float:
    """The collisions a second that a process of `start` printed, once `release`d."""
    out, _ = process.communicate()
    if process.returncode != 0:
        raise SystemExit(f"bench_paired: a W1 run failed (exit {process.returncode})")
    return float(out.split()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("a", help=f"the revision to compare against (or {WORKTREE})")
    parser.add_argument("b", help=f"the revision compared (or {WORKTREE})")
    parser.add_argument("--n", type=float, default=1e6, help="disks (default 1e6)")
    parser.add_argument("--rounds", type=int, default=4, help="rounds of both at once")
    parser.add_argument("--repeats", type=int, default=5, help="W1's repeats a run")
    args = parser.parse_args()
    if len(os.sched_getaffinity(0)) < 2:
        raise SystemExit("bench_paired: needs two cores, one for each revision")
    core_a, core_b = sorted(os.sched_getaffinity(0))[:2]
    with tempfile.TemporaryDirectory(prefix="bench_paired_") as scratch:
        here = Path(scratch)
        sources = [checkout(rev, here / f"tree{i}") for i, rev in enumerate((args.a, args.b))]
        caches = [here / "cache0", here / "cache1"]
        try:
            for source, cache in zip(sources, caches, strict=True):  # compile, one at a time
                first = start(source, cache, core_a, 10_000, 1)
                warmed(first)
                release(first)
                rate(first)
            ratios = []
            for round_ in range(args.rounds):
                cores = (core_a, core_b) if round_ % 2 == 0 else (core_b, core_a)
                order = (0, 1) if round_ % 2 == 0 else (1, 0)
                runs = {i: start(sources[i], caches[i], cores[i], int(args.n), args.repeats)
                        for i in order}  # fmt: skip
                for i in order:
                    warmed(runs[i])
                for i in order:  # both time at once
                    release(runs[i])
                a, b = rate(runs[0]), rate(runs[1])
                ratios.append(b / a)
                print(f"round {round_ + 1}: A {a:.4g}/s  B {b:.4g}/s  B/A {b / a:.3f}", flush=True)
            print(f"B/A over {args.rounds} rounds: {min(ratios):.3f} to {max(ratios):.3f}")
        finally:
            for source in sources:
                if source != ROOT / "src":
                    subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                                    str(source.parent)], check=False)  # fmt: skip


if __name__ == "__main__":
    main()
