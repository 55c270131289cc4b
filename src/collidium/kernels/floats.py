"""Float tricks the compiled loops share: a float64 read as its bit pattern, and back.

The bit patterns of non-negative floats order as the floats do, so the largest of many
magnitudes can be taken as an integer maximum, which LLVM vectorises (a float maximum it does
not). Without the sign bit a NaN has a larger pattern than any number, infinity included, so it
is kept.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, cast

from numba import types
from numba.extending import intrinsic

from collidium.kernels.compilation import uncounted

#: All bits of a float64 but its sign.
MAGNITUDE = (1 << 63) - 1


def _bitcast(source: types.Type, target: types.Type) -> Callable[[Any], Any]:
    """A compiled function that reads a value of one 64-bit type as another (no conversion)."""

    def typer(typingctx: Any, value: Any) -> Any:
        def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
            return builder.bitcast(args[0], context.get_value_type(target))

        return target(source), codegen

    return cast(Callable[[Any], Any], intrinsic(typer))


#: The bit pattern of a float64 as an int64, and back.
bits = _bitcast(types.float64, types.int64)
from_bits = _bitcast(types.int64, types.float64)


@uncounted()
def largest_magnitude(values: Any) -> float:
    """``max |v|`` over the entries of ``values`` (N, 2), as NumPy's ``max(abs(values))``
    gives it: NaN if any entry is NaN, 0 for none. One pass without branches."""
    largest = 0
    for i in range(values.shape[0]):
        largest = max(largest, bits(values[i, 0]) & MAGNITUDE, bits(values[i, 1]) & MAGNITUDE)
    return from_bits(largest)
