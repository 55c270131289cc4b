"""The first-compile hook: called once when numba compiles, never for a kernel it already has."""

from __future__ import annotations

import numba

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
