"""Compiling: the first-compile hook (called once when numba compiles, never for a kernel it
already has), and what keeps numba's cache sound."""

from __future__ import annotations

import importlib
import inspect
import os
import pkgutil
import shutil
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import numba
import numpy as np
import pytest
from numba.core import event as numba_event
from numba.core.registry import CPUDispatcher as Dispatcher

import collidium.kernels
from collidium.kernels.compilation import (
    interrupts_outside_compiling,
    kernel_sources_digest,
    on_first_compile,
    prefetch,
)


def _fresh_kernel():
    """A kernel numba has never compiled (no cache: each test makes its own)."""

    @numba.njit
    def twice(x):
        return 2 * x

    return twice


class _InterruptAtCompile(numba_event.Listener):
    """Presses Ctrl+C as numba starts compiling."""

    def on_start(self, event: numba_event.Event) -> None:
        signal.raise_signal(signal.SIGINT)

    def on_end(self, event: numba_event.Event) -> None:
        pass


def test_a_ctrl_c_during_a_compile_is_raised_once_the_kernel_is_whole():
    """Raised inside numba's compiler, the interrupt would leave the kernel half made (no
    signature; in the engine, libraries that the next kernel fails to link)."""
    kernel, before = _fresh_kernel(), signal.getsignal(signal.SIGINT)
    listener = _InterruptAtCompile()
    numba_event.register("numba:compile", listener)
    try:
        with interrupts_outside_compiling(), pytest.raises(KeyboardInterrupt):
            kernel(1.0)
    finally:
        numba_event.unregister("numba:compile", listener)
    assert len(kernel.signatures) == 1
    assert kernel(2.0) == 4.0
    with interrupts_outside_compiling(), pytest.raises(KeyboardInterrupt):
        signal.raise_signal(signal.SIGINT)  # outside a compile: at once
    assert signal.getsignal(signal.SIGINT) is before  # put back


def test_the_callback_runs_once_at_the_first_compile_and_not_after_the_block():
    calls = []
    first, second, after = _fresh_kernel(), _fresh_kernel(), _fresh_kernel()
    with on_first_compile(lambda: calls.append(len(calls))):
        assert calls == []
        assert first(2) == 4  # compiles
        assert second(2.0) == 4.0  # compiles again: the callback is not called twice
        assert first(3) == 6  # compiled already
    assert after(1) == 2
    assert calls == [0]


def test_no_compile_no_call():
    kernel = _fresh_kernel()
    kernel(1)
    calls = []
    with on_first_compile(lambda: calls.append(1)):
        kernel(2)
    assert calls == []


#: A run of a small kernel in a copy of the package: where collidium came from, and how many
#: times the kernel came from numba's cache.
_CACHE_HITS = """
import numpy as np
import collidium
from collidium.kernels.sums import kinetic_energy
kinetic_energy(np.ones(3), np.ones((3, 2)))
print(collidium.__file__, sum(kinetic_energy.stats.cache_hits.values()))
"""


def test_a_kernels_cache_is_used_until_any_kernel_changes(tmp_path):
    """Each kernel's cache is stamped with every kernel's source: in a copy of the package, a
    kernel compiled once is loaded from its cache, and compiled again after an edit (a comment)
    of another kernel's file alone, which numba's own stamp, its file's content, misses. The copy's
    stamp is the package's, whatever its place, as a wheel's compiled kernels need."""
    shutil.copytree(Path(collidium.__file__).parent, tmp_path / "collidium",
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    kernels = tmp_path / "collidium" / "kernels"
    assert kernel_sources_digest(kernels) == kernel_sources_digest()
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"} | {
        "PYTHONPATH": str(tmp_path)
    }

    def hits() -> int:
        result = subprocess.run([sys.executable, "-c", _CACHE_HITS], env=env, cwd=tmp_path,
                                capture_output=True, text=True, check=True)  # fmt: skip
        source, count = result.stdout.split()
        assert Path(source).is_relative_to(tmp_path)
        return int(count)

    assert [hits(), hits()] == [0, 1]
    with (kernels / "event_queue.py").open("a") as source:
        source.write("# an edit of the event queue alone\n")
    assert [hits(), hits()] == [0, 1]


def _kernels() -> list[tuple[str, Any]]:
    """Every compiled kernel of `collidium.kernels`, by qualified name."""
    found = []
    for info in pkgutil.walk_packages(collidium.kernels.__path__, "collidium.kernels."):
        module = importlib.import_module(info.name)
        for name, value in vars(module).items():
            if isinstance(value, Dispatcher) and value.py_func.__module__ == info.name:
                found.append((f"{info.name}.{name}", value))
    return found


def _callees(kernel: Any) -> list[Any]:
    """The compiled kernels a kernel's code names: globals of its module, and attributes of the
    modules it names (``events.run_events``)."""
    scope = kernel.py_func.__globals__
    names = kernel.py_func.__code__.co_names
    named = [scope.get(word) for word in names]
    named += [
        vars(module).get(word)  # not getattr: NumPy 1.26 warns of its deprecated aliases
        for module in named
        if inspect.ismodule(module)
        for word in names
    ]
    return [callee for callee in named if isinstance(callee, Dispatcher) and callee is not kernel]


def test_no_compiled_kernel_calls_a_parallel_one():
    """A kernel that calls a parallel one breaks numba's cache: once the caller is compiled
    against a callee loaded from the cache, the next process that loads the caller crashes
    (reproduced with the stiffness of 300 charges). The choice of a parallel kernel is made in
    Python instead."""
    kernels = _kernels()
    parallel = {id(k) for _, k in kernels if k.targetoptions.get("parallel")}
    assert parallel, "the kernels' parallel loops were not found"
    offenders = [
        name for name, kernel in kernels for callee in _callees(kernel) if id(callee) in parallel
    ]
    assert offenders == []


def test_what_a_kernel_without_reference_counting_calls_sets_its_own():
    """numba compiles a kernel with its caller's reference counting unless the kernel sets its
    own (`_nrt`). One that allocates, called first from a kernel compiled without counting
    (`collidium.kernels.compilation.uncounted`), then fails to compile, but only on a fresh
    cache and in that order: the compiled substeps' sweep (`sorting.sort_nearly_sorted`) did,
    on a first run of `orbit`. So every kernel that such a kernel calls sets `_nrt` itself,
    unless numba inlines it into its caller (``inline="always"``), whose callees then count as
    the caller's."""
    uncounted = [k for _, k in _kernels() if k.targetoptions.get("_nrt") is False]
    assert uncounted, "the kernels without reference counting were not found"
    offenders, seen, callers = set(), set(), list(uncounted)
    while callers:
        for callee in _callees(callers.pop()):
            options = callee.targetoptions
            if id(callee) in seen or options.get("_nrt") is not None:
                continue
            seen.add(id(callee))
            callers.append(callee)  # its own callees inherit the caller's counting too
            if options.get("inline") != "always":
                offenders.add(f"{callee.py_func.__module__}.{callee.py_func.__qualname__}")
    assert sorted(offenders) == []


def test_prefetch_asks_for_the_lines_of_arrays_of_any_type_and_changes_nothing():
    """`prefetch` compiles for arrays of two types and dimensions in one kernel (one declaration
    of LLVM's intrinsic for all) into the processor's prefetch, and the values read are as they
    were."""

    @numba.njit
    def summed(a, b):
        total = 0.0
        for i in range(a.shape[0]):
            prefetch(a, i)
            prefetch(b, (i, 1))
            total += a[i] + b[i, 1]
        return total

    a, b = np.arange(100.0), np.arange(300, dtype=np.int32).reshape(100, 3)
    assert summed(a, b) == a.sum() + b[:, 1].sum()
    assembly = next(iter(summed.inspect_asm().values()))
    assert "prefetch" in assembly or "prfm" in assembly  # x86, ARM
