"""When the kernels compile: on a fresh numba cache the first run compiles them (tens of seconds
on a laptop, silent otherwise); later runs load them from the cache in well under a second.

numba announces each real compilation, and not a load from its cache, as a ``numba:compile``
event (its event API); `on_first_compile` turns the first such event into one call, so that a
command line can say at once why nothing happens yet. `interrupts_outside_compiling` holds a
Ctrl+C back while numba compiles or loads a kernel, which it cannot survive.

numba stamps each kernel's cache with its own source file alone, yet a kernel's compiled code
holds every kernel it calls, from other files too: after an edit of `events` alone, the cached
substeps ran the event loop as it was, on arrays laid out as it is now (a crash). So
`stamp_caches_with_every_kernel` stamps the caches of the kernels with every kernel's source.
"""

from __future__ import annotations

import functools
import hashlib
import signal
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import FrameType
from typing import Any

import numba
from llvmlite import ir
from numba.core import caching, cgutils, types
from numba.core import event as numba_event
from numba.extending import intrinsic

#: The kernels' package: the sources that every kernel's cache is stamped with.
KERNELS = Path(__file__).resolve().parent


@functools.cache
def kernel_sources_digest(folder: Path = KERNELS) -> str:
    """SHA-256 of every Python file under ``folder`` (the kernels' package), by path within it
    and content: the same for a copy (a wheel's build, `collidium.precompile`), whatever its
    place or files' times. Read once a process, as numba reads a kernel's own source."""
    digest = hashlib.sha256()
    for path in sorted(folder.rglob("*.py")):
        digest.update(path.relative_to(folder).as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


def _stamped_with_every_kernel(locator: type) -> type:
    """numba's cache ``locator`` (a class) for the kernels' files alone, their caches stamped
    with `kernel_sources_digest` instead of their own file's content."""

    class KernelsLocator(locator):
        stamps_every_kernel = True

        @classmethod
        def from_function(cls, py_func: Any, py_file: str) -> Any:
            if not Path(py_file).resolve().is_relative_to(KERNELS):
                return None  # numba's own locators then serve it
            return super().from_function(py_func, py_file)

        def get_source_stamp(self) -> str:
            return kernel_sources_digest()

    KernelsLocator.__name__ = KernelsLocator.__qualname__ = f"Kernels{locator.__name__}"
    return KernelsLocator


def stamp_caches_with_every_kernel() -> None:
    """Put, before numba's own, locators that stamp the kernels' caches with every kernel's
    source (`kernel_sources_digest`): an edit of any kernel compiles them all again, and none
    loads code compiled against another version of the kernels it calls. For the kernels
    decorated after it (`collidium.kernels` calls it first); once is enough."""
    named = vars(caching)
    impl = named.get("CacheImpl") or named["_CacheImpl"]  # the older name
    if any(getattr(cls, "stamps_every_kernel", False) for cls in impl._locator_classes):
        return
    ours = [_stamped_with_every_kernel(cls) for cls in impl._locator_classes
            if issubclass(cls, caching._SourceFileBackedLocatorMixin)]  # fmt: skip
    impl._locator_classes = [*ours, *impl._locator_classes]


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


class _CompilerDepth(numba_event.Listener):
    """How deep the main thread is in numba's compiler lock (held while numba compiles a kernel
    or loads one from its cache); raises a Ctrl+C held back meanwhile once it has left it."""

    def __init__(self) -> None:
        self.depth = 0
        self.held = False

    def on_start(self, event: numba_event.Event) -> None:
        if threading.current_thread() is threading.main_thread():
            self.depth += 1

    def on_end(self, event: numba_event.Event) -> None:
        if threading.current_thread() is not threading.main_thread():
            return
        self.depth -= 1
        if self.depth == 0 and self.held:  # the lock is released: numba is whole again
            self.held = False
            raise KeyboardInterrupt


@contextmanager
def interrupts_outside_compiling() -> Iterator[None]:
    """Within the block (entered on the main thread), a Ctrl+C (SIGINT) that arrives while numba
    compiles or loads a kernel is raised as soon as it is done, not inside it: interrupted there,
    numba keeps a half-made library, and the next kernel that links it fails with a traceback
    (``RuntimeError: no compiled object yet``). Elsewhere a Ctrl+C raises at once, as usual."""
    if threading.current_thread() is not threading.main_thread():  # signals go to the main one
        yield
        return
    depth = _CompilerDepth()

    def on_interrupt(signum: int, frame: FrameType | None) -> None:
        if depth.depth > 0:
            depth.held = True
        else:
            raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, on_interrupt)
    numba_event.register("numba:compiler_lock", depth)
    try:
        yield
    finally:
        numba_event.unregister("numba:compiler_lock", depth)
        signal.signal(signal.SIGINT, previous)


def _prefetch(typingctx: Any, array: Any, index: Any) -> Any:
    """Ask the processor for the cache line of ``array[index]`` (an index within the array, a
    tuple of them for an array of more dimensions), to be read soon: LLVM's ``llvm.prefetch``,
    which changes nothing else. The event loop (`collidium.kernels.events`) asks so for what the
    next events will read while this one runs."""
    signature = types.void(array, index)

    def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
        array_type = sig.args[0]
        view = context.make_array(array_type)(context, builder, args[0])
        index_type = sig.args[1]
        if isinstance(index_type, types.BaseTuple):
            kinds: Any = index_type  # iterates over its members' types
            values = cgutils.unpack_tuple(builder, args[1], len(kinds))
            given = list(zip(values, kinds, strict=True))
        else:
            given = [(args[1], index_type)]
        indices = [context.cast(builder, value, kind, types.intp) for value, kind in given]
        pointer = cgutils.get_item_pointer(
            context, builder, array_type, view, indices, wraparound=False
        )
        word, byte = ir.IntType(32), ir.IntType(8).as_pointer()
        # One declaration per module, whatever the arrays' types: hence the byte pointer, its
        # name mangled as this LLVM wants it.
        function = builder.module.declare_intrinsic(
            "llvm.prefetch", [byte], ir.FunctionType(ir.VoidType(), [byte, word, word, word])
        )
        builder.call(function, [builder.bitcast(pointer, byte), word(0), word(3), word(1)])
        return context.get_dummy_value()  # above: a read, kept in every cache level, of data

    return signature, codegen


#: `_prefetch` as kernels call it, ``prefetch(array, index)`` (typed for them by numba).
prefetch: Any = intrinsic(_prefetch)
