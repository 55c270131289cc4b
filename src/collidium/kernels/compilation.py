"""When the kernels compile: on a fresh numba cache the first run compiles them (tens of seconds
on a laptop, silent otherwise); later runs load them from the cache in well under a second.

numba announces each real compilation, and not a load from its cache, as a ``numba:compile``
event (its event API); `on_first_compile` turns the first such event into one call, so that a
command line can say at once why nothing happens yet.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager

from numba.core import event as numba_event


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
