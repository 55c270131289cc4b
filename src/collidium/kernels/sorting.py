"""Sorts shared by the kernels.

`radix_sort`, for the tree's Morton order and the step mode's pairs: a comparison sort of random
keys mispredicts a branch per comparison; an LSD radix sort makes a few passes of counting and
scattering instead, and is stable, so equal keys keep their order. `sort_nearly_sorted`, for
lists that moved little since they were last sorted: the step mode's movers between cells, the
compiled substeps' sweep.
"""

from __future__ import annotations

import numba
import numpy as np

from collidium.kernels.compilation import counted

#: Unsigned indices: no wraparound of negative ones.
_u = numba.uint64

#: Bits sorted per pass: 2048 counters fit in the L1 cache.
DIGIT_BITS = 11


@numba.njit(cache=True)
def radix_sort(
    keys: np.ndarray,
    keys_spare: np.ndarray,
    bits: int,
    values: np.ndarray,
    values_spare: np.ndarray,
) -> None:
    """Sort ``keys`` in place, stably, carrying ``values`` along (pass empty arrays for none).

    Parameters
    ----------
    keys : ndarray of int64, shape (M,)
        Non-negative keys below ``2**bits``; sorted on return.
    keys_spare : ndarray of int64, shape (M,)
        Work array.
    bits : int
        Number of low bits that can be set in a key.
    values, values_spare : ndarray, shape (M,) or (0,)
        Payload permuted with the keys, and its work array; both empty for keys alone.
    """
    carry = values.shape[0] > 0
    buckets = 1 << DIGIT_BITS
    mask = buckets - 1
    count = np.empty(buckets, dtype=np.int64)
    source_keys, target_keys = keys, keys_spare
    source_values, target_values = values, values_spare
    passes = (bits + DIGIT_BITS - 1) // DIGIT_BITS
    for p in range(passes):
        shift = p * DIGIT_BITS
        count[:] = 0
        for i in range(keys.shape[0]):
            count[(source_keys[i] >> shift) & mask] += 1
        total = 0
        for b in range(buckets):
            size = count[b]
            count[b] = total
            total += size
        for i in range(keys.shape[0]):
            b = (source_keys[i] >> shift) & mask
            target_keys[count[b]] = source_keys[i]
            if carry:
                target_values[count[b]] = source_values[i]
            count[b] += 1
        source_keys, target_keys = target_keys, source_keys
        source_values, target_values = target_values, source_values
    if passes % 2 == 1:
        keys[:] = keys_spare
        if carry:
            values[:] = values_spare


@counted()  # its merge sort allocates, and the compiled substeps call it
def sort_nearly_sorted(index: np.ndarray, key: np.ndarray) -> None:
    """Stable sort of ``index`` (M,) in place by ``key[index]``, for a list that is nearly in
    order already: an insertion sort has little to do; past a budget of shifts a merge sort takes
    over."""
    m = index.shape[0]
    budget = 64 * m + 1024
    for t in range(1, m):
        s = index[t]
        c = key[_u(s)]
        u = t
        while u > 0 and key[_u(index[u - 1])] > c:
            index[u] = index[u - 1]
            u -= 1
        index[u] = s
        budget -= t - u
        if budget < 0:
            index[:] = index[np.argsort(key[index], kind="mergesort")]
            return
