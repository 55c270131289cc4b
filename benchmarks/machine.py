"""The machine a benchmark runs on: a busy one, as a laptop with another program running is."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def busy_cores(count: int | None = None) -> Iterator[int]:
    """``count`` CPU-bound processes (a Python busy loop each; default one per core) for the
    duration of the block, which receives the count."""
    if count is None:
        count = os.cpu_count() or 1
    loops = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(count)]
    try:
        time.sleep(0.5)  # let them reach the scheduler
        yield count
    finally:
        for loop in loops:
            loop.kill()
            loop.wait()
