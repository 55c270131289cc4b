"""Compiling: the first-compile hook (called once when numba compiles, never for a kernel it
already has), and what keeps numba's cache sound."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
from typing import Any

import numba
from numba.core.registry import CPUDispatcher as Dispatcher

import collidium.kernels
from collidium.kernels.compilation import on_first_compile


def _fresh_kernel():
    """A kernel numba has never compiled (no cache: each test makes its own)."""

    @numba.njit
    def twice(x):
        return 2 * x

    return twice


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


def _kernels() -> list[tuple[str, Any]]:
    """Every compiled kernel of `collidium.kernels`, by qualified name."""
    found = []
    for info in pkgutil.walk_packages(collidium.kernels.__path__, "collidium.kernels."):
        module = importlib.import_module(info.name)
        for name, value in vars(module).items():
            if isinstance(value, Dispatcher) and value.py_func.__module__ == info.name:
                found.append((f"{info.name}.{name}", value))
    return found


def test_no_compiled_kernel_calls_a_parallel_one():
    """A kernel that calls a parallel one breaks numba's cache: once the caller is compiled
    against a callee loaded from the cache, the next process that loads the caller crashes
    (reproduced with the stiffness of 300 charges). The choice of a parallel kernel is made in
    Python instead."""
    kernels = _kernels()
    parallel = {id(k) for _, k in kernels if k.targetoptions.get("parallel")}
    assert parallel, "the kernels' parallel loops were not found"
    offenders = []
    for name, kernel in kernels:
        scope = kernel.py_func.__globals__
        called = [scope.get(word) for word in kernel.py_func.__code__.co_names]
        called += [
            vars(module).get(word)  # not getattr: NumPy 1.26 warns of its deprecated aliases
            for module in called
            if inspect.ismodule(module)
            for word in kernel.py_func.__code__.co_names
        ]
        offenders += [name for callee in called if id(callee) in parallel and callee is not kernel]
    assert offenders == []
