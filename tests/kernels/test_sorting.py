"""The shared radix sort against NumPy's stable sort."""

from __future__ import annotations

import numpy as np
import pytest

from collidium.kernels.sorting import radix_sort, sort_nearly_sorted


@pytest.mark.parametrize(("size", "bits"), [(1, 5), (300, 5), (5000, 11), (5000, 30), (4000, 42)])
def test_radix_sort_is_numpys_stable_sort(rng, size, bits):
    """Same sorted keys, and the payload in the stable order: equal keys (many, with few bits)
    keep their original order. Odd and even numbers of passes both end in the given arrays."""
    keys = rng.integers(0, 2**bits, size, dtype=np.int64)
    values = np.arange(size, dtype=np.int64)
    want = np.argsort(keys, kind="stable")
    sorted_keys = keys.copy()
    radix_sort(sorted_keys, np.empty_like(keys), bits, values, np.empty_like(values))
    np.testing.assert_array_equal(sorted_keys, keys[want])
    np.testing.assert_array_equal(values, want)


def test_radix_sort_without_payload(rng):
    keys = rng.integers(0, 2**20, 3000, dtype=np.int64)
    sorted_keys = keys.copy()
    none = np.empty(0, dtype=np.int64)
    radix_sort(sorted_keys, np.empty_like(keys), 20, none, none)
    np.testing.assert_array_equal(sorted_keys, np.sort(keys))


@pytest.mark.parametrize("shuffled", [0.01, 1.0])
def test_sort_nearly_sorted_is_numpys_stable_sort(rng, shuffled):
    """A list with 1% of its keys moved (insertion sort) and one in random order (past the
    budget of shifts: the merge sort), with repeated keys: the order of a stable sort."""
    key = np.round(np.sort(rng.uniform(0.0, 100.0, 5000)))  # repeated values: stability shows
    moved = rng.random(key.shape[0]) < shuffled
    key[moved] = rng.permutation(key[moved])
    index = np.arange(key.shape[0])
    sort_nearly_sorted(index, key)
    np.testing.assert_array_equal(index, np.argsort(key, kind="stable"))
