"""The exact engine's event queue: the earliest event in the order (time, ident), always."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from collidium.kernels import event_queue


@numba.njit(_nrt=False)
def earliest_slot(keys, items, ident):
    """The slot `event_queue.earliest` takes first (a kernel: the queue's parts are views)."""
    return event_queue.earliest(event_queue.views(keys, items), ident)


@numba.njit(_nrt=False)
def _update(k, t, keys, items, ident):
    event_queue.update(k, t, event_queue.views(keys, items), ident)


def _queue(times: np.ndarray, ident: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A queue built from the slots' ``times``."""
    float_size, int_size = event_queue.sizes(times.shape[0])
    keys = np.empty(float_size)
    items = np.empty(int_size, dtype=np.int32)
    keys[: times.shape[0]] = times
    event_queue.build(keys, items, ident)
    return keys, items


@pytest.mark.parametrize("n", [1, 9, 73, 600, 5000])
def test_the_queue_takes_events_in_time_then_ident_order(rng, n):
    """Equal times at every level (within a block, between blocks, between superblocks in the
    heap) are taken by ident, whatever the slots' order."""
    times = rng.choice([1.0, 2.0, 3.0], n)  # many ties everywhere
    ident = rng.permutation(n).astype(np.int32)
    keys, items = _queue(times, ident)
    taken = []
    for _ in range(n):
        k = earliest_slot(keys, items, ident)
        taken.append(k)
        _update(k, np.inf, keys, items, ident)
    assert taken == np.lexsort((ident, times)).tolist()


@pytest.mark.parametrize("n", [5, 300, 4000])
def test_updates_keep_the_earliest_in_front(rng, n):
    """As the engine does: the earliest slot gets a later time, and another (its partner) an
    earlier or a later one, or inf (no event); the queue's first is then always the first of
    (time, ident) over every slot."""
    times = rng.integers(0, 50, n).astype(float)
    ident = rng.permutation(n).astype(np.int32)
    keys, items = _queue(times, ident)
    for _ in range(3000):
        k = earliest_slot(keys, items, ident)
        assert k == np.lexsort((ident, keys[:n]))[0]
        _update(k, keys[k] + rng.integers(0, 30), keys, items, ident)
        partner = rng.integers(n)
        later = rng.choice([keys[k], keys[k] + rng.integers(0, 30), np.inf])
        _update(partner, later, keys, items, ident)


def test_the_sizes_leave_room_for_the_padding_and_align_the_heap():
    """The slots are padded to whole superblocks; the heap's node 1 starts a cache line when
    ``keys`` and ``items`` do (as the engine allocates them)."""
    for n in (1, event_queue.SUPER, event_queue.SUPER + 1, 10**6):
        slots = event_queue.padded(n)
        assert slots >= n and slots % event_queue.SUPER == 0
        float_size, int_size = event_queue.sizes(n)
        blocks, supers = slots // event_queue.BLOCK, slots // event_queue.SUPER
        heap = slots + blocks + event_queue._KEYS_GAP - 1
        assert float_size == heap + 1 + supers and (heap + 1) * 8 % 64 == 0
        assert ((blocks + event_queue._ITEMS_GAP) * 4) % 64 == 0
        assert int_size == blocks + event_queue._ITEMS_GAP + 2 * supers
