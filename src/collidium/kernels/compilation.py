"""When the kernels compile: on a fresh numba cache the first run compiles them (tens of seconds
on a laptop, silent otherwise); later runs load them from the cache in well under a second.

numba announces each real compilation, and not a load from its cache, as a ``numba:compile``
event (its event API); `on_first_compile` turns the first such event into one call, so that a
command line can say at once why nothing happens yet.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numba
from numba.core import event as numba_event


def uncounted(**options: Any) -> Any:
    """numba.njit, cached, for kernels that allocate nothing: compiled without numba's
    reference counting, which cannot prune the atomic counts it emits around array arguments
    when they span branches (numba issue #2350; with them the exact engine's prediction cost
    five times as much, 150 against 30 ns at 1,000 disks).

    A kernel that such a kernel calls must set its own counting (this, or `counted` where it
    allocates): numba compiles it with its first caller's otherwise, and one that allocates
    then fails to compile, on a fresh cache only (``tests/kernels/test_compilation.py``)."""
    return numba.njit(**{"cache": True, "_nrt": False, **options})


def counted(**options: Any) -> Any:
    """numba.njit, cached, with numba's reference counting on by choice, for a kernel that
    allocates and that kernels compiled without counting (`uncounted`) call: numba would
    otherwise compile it with its first caller's, and fail."""
    return numba.njit(**{"cache": True, "_nrt": True, **options})


#: For the helpers of such kernels: LLVM inlines them into their callers (numba's
#: ``forceinline``), and numba types each once; ``inline="always"`` inlines at numba's level
#: and types every copy again, most of a minute of the exact engine's first compilation
#: (ARCHITECTURE.md, "Compile time").
inlined = uncounted(forceinline=True)


class _FirstCompile(numba_event.Listener):
    """Calls its callback at the start of the first compilation it hears of, once."""

    def __init__(self, callback: Callable[[], None]) -> None:
        self.callback: Callable[[], None] | None = callback

    def on_start(self, event: numba_event.Event) -> None:
        callback, self.callback = self.callback, None
        if callback is not None:
            callback()

    def on_end(self, event: numba_event.Event) -> None:
        pass


@contextmanager
def on_first_compile(callback: Callable[[], None]) -> Iterator[None]:
    """Within the block, call ``callback()`` (no arguments) once, when numba first compiles a
    kernel rather than loading it from its cache; never if every kernel comes from the cache."""
    listener = _FirstCompile(callback)
    numba_event.register("numba:compile", listener)
    try:
        yield
    finally:
        numba_event.unregister("numba:compile", listener)
