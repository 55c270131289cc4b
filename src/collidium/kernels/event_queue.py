"""The exact engine's event queue: each slot's next event time, taken in the order (time, ident).

Layout. At a million disks an event waits on memory, and a heap of every slot waited at each of
its lower levels in turn (ARCHITECTURE.md, "The queue of blocks"). So:

- ``times[k]`` is slot k's event time (s), in slot order. The slots are padded to a multiple of
  `SUPER` with slots whose time is inf.
- Blocks of `BLOCK` consecutive slots (two cache lines of times) each keep their earliest
  event: ``block_times[b]`` and its slot ``block_slots[b]``.
- Superblocks of `BLOCK` blocks are ordered by their earliest time in an 8-ary heap:
  ``heap_times``, its slots ``heap_slots`` and each superblock's place in it, ``places``. At a
  million disks the heap has 4,000 entries, in a core's own cache.

A slot's new time updates its block, and where that block's earliest changed, its superblock's
and the heap. Every line that this reads is known from the slot alone, so the event loop asks for
them an event ahead (`collidium.kernels.events`). Each level breaks ties between equal times by
ident, so the earliest is that of the order (time, ident), whatever the slots' order.

The engine keeps the queue in two arrays, so that kernels take it as two arguments: ``keys``
(float64) holds the times, ``items`` (int32) the slots and places. `views` gives the parts, in
kernels. The slots' times come first in ``keys``, where the passes that predict every slot write
them before `build`; the heap's part starts one entry before a cache line, so that a node's eight
children share one.
"""

from __future__ import annotations

import math

from collidium.kernels.compilation import inlined, prefetch, uncounted

#: Slots a block, and blocks a superblock: a block's times are two cache lines.
BLOCK = 16
SUPER = BLOCK * BLOCK

#: Children per node of the superblocks' heap: 8 keys fill one 64-byte line.
ARITY = 8

#: Entries before the heap's times in ``keys`` and before its slots in ``items`` that are not
#: block entries: they put its node 1 at the start of a cache line.
_KEYS_GAP = ARITY
_ITEMS_GAP = BLOCK


def padded(n: int) -> int:
    """Slots of a queue of n disks: a multiple of `SUPER`, at least one superblock."""
    return max(-(-n // SUPER), 1) * SUPER


def sizes(n: int) -> tuple[int, int]:
    """Lengths of ``keys`` and ``items`` for n disks."""
    slots = padded(n)
    blocks, supers = slots // BLOCK, slots // SUPER
    return slots + blocks + _KEYS_GAP + supers, blocks + _ITEMS_GAP + 2 * supers


@inlined
def views(keys, items):
    """The queue's parts: ``times``, ``block_times``, ``heap_times`` (float64) and
    ``block_slots``, ``heap_slots``, ``places`` (int32), views of ``keys`` and ``items``.

    Only for kernels compiled without reference counting (`uncounted`), as the engine's are: a
    kernel that counts references would release views it never held."""
    slots = (keys.shape[0] - _KEYS_GAP) // (SUPER + BLOCK + 1) * SUPER
    blocks, supers = slots // BLOCK, slots // SUPER
    heap = slots + blocks + _KEYS_GAP - 1
    first = blocks + _ITEMS_GAP - 1
    return (keys[:slots], keys[slots : slots + blocks], keys[heap : heap + supers],
            items[:blocks], items[first : first + supers],
            items[first + supers : first + 2 * supers])  # fmt: skip


# --- the least of a group, ties by ident ---------------------------------------------------------


@inlined
def _least(a, b, ia, ib):
    """The lesser of keys a and b with its index (ia, ib); a on a tie. Selects, not branches."""
    later = b < a
    return (b if later else a), (ib if later else ia)


@inlined
def least_of_eight(values, first):
    """``(index, value)`` of the least of ``values[first:first + 8]``, the first on a tie: a
    tournament of pairs, three compares deep rather than seven in a row, without branches (which
    way the minimum goes is a coin toss, and a mispredicted branch costs more than the
    compares)."""
    v01, i01 = _least(values[first], values[first + 1], 0, 1)
    v23, i23 = _least(values[first + 2], values[first + 3], 2, 3)
    v45, i45 = _least(values[first + 4], values[first + 5], 4, 5)
    v67, i67 = _least(values[first + 6], values[first + 7], 6, 7)
    v03, i03 = _least(v01, v23, i01, i23)
    v47, i47 = _least(v45, v67, i45, i67)
    v, i = _least(v03, v47, i03, i47)
    return first + i, v


@inlined
def _least_of_block(values, first):
    """``(index, value)`` of the least of ``values[first:first + BLOCK]``, the first on a tie,
    and how many equal it."""
    i, v = least_of_eight(values, first)
    i2, v2 = least_of_eight(values, first + 8)
    later = v2 < v
    v = v2 if later else v
    i = i2 if later else i
    equal = 0
    for c in range(first, first + BLOCK):
        equal += values[c] == v
    return i, v, equal


@uncounted()
def _tied_slot(values, first, slots, ident):
    """The slot of lowest ident among the equal least of ``values[first:first + BLOCK]``, where
    entry c is slot ``slots[c]``, or slot c where ``slots`` is empty (one type either way: one
    compilation). Padding slots (past ``ident``'s) come last."""
    least = values[first]
    for c in range(first + 1, first + BLOCK):
        least = min(least, values[c])
    n = ident.shape[0]
    best = -1
    for c in range(first, first + BLOCK):
        if values[c] == least:
            s = c if slots.shape[0] == 0 else slots[c]
            if best < 0 or (s < n and (best >= n or ident[s] < ident[best])):
                best = s
    return best


@inlined
def _block_earliest(b, times, block_slots, ident):
    """``(time, slot)`` of block b's earliest event."""
    i, v, equal = _least_of_block(times, b * BLOCK)
    return v, (i if equal == 1 else _tied_slot(times, b * BLOCK, block_slots[:0], ident))


@inlined
def _super_earliest(s, block_times, block_slots, ident):
    """``(time, slot)`` of superblock s's earliest event."""
    i, v, equal = _least_of_block(block_times, s * BLOCK)
    if equal == 1:
        return v, block_slots[i]
    return v, _tied_slot(block_times, s * BLOCK, block_slots, ident)


# --- the heap of superblocks ---------------------------------------------------------------------


@inlined
def _put(node, key, slot, heap_times, heap_slots, places) -> None:
    """Write ``(key, slot)`` at ``node`` of the heap, and the node as its superblock's place."""
    heap_times[node] = key
    heap_slots[node] = slot
    places[slot // SUPER] = node


@inlined
def _sift_up(node, key, slot, heap_times, heap_slots, places) -> int:
    """Move ``(key, slot)`` up from ``node`` to its place; return where it landed."""
    while node > 0:
        parent = (node - 1) // ARITY
        if heap_times[parent] <= key:
            break
        _put(node, heap_times[parent], heap_slots[parent], heap_times, heap_slots, places)
        node = parent
    _put(node, key, slot, heap_times, heap_slots, places)
    return node


@inlined
def _sift_down(node, key, slot, heap_times, heap_slots, places) -> None:
    """Move ``(key, slot)`` down from ``node`` to its place."""
    n = heap_times.shape[0]
    while True:
        first = ARITY * node + 1
        if first >= n:
            break
        if first + ARITY <= n:
            child, least = least_of_eight(heap_times, first)
        else:
            child = first
            least = heap_times[first]
            for c in range(first + 1, n):
                if heap_times[c] < least:
                    child = c
                    least = heap_times[c]
        if key <= least:
            break
        _put(node, least, heap_slots[child], heap_times, heap_slots, places)
        node = child
    _put(node, key, slot, heap_times, heap_slots, places)


@inlined
def _heap_update(s, key, slot, heap_times, heap_slots, places) -> None:
    """Give superblock s the earliest ``(key, slot)`` and restore the heap's order."""
    node = places[s]
    if _sift_up(node, key, slot, heap_times, heap_slots, places) == node:
        _sift_down(node, key, slot, heap_times, heap_slots, places)


@uncounted()
def _earliest_tied(heap_times, heap_slots, ident) -> int:
    """Among the heap's entries whose time equals the root's, the slot with the lowest ident.

    Heap order puts every such entry in a subtree at the root (its ancestors can be neither later
    nor earlier), so the search goes down level by level through the span of children of the
    tied entries found on the level above.
    """
    n = heap_times.shape[0]
    tied = heap_times[0]
    best = heap_slots[0]
    lo = hi = 0
    while ARITY * lo + 1 < n:
        found_lo = found_hi = -1
        for c in range(ARITY * lo + 1, min(ARITY * hi + ARITY + 1, n)):
            if heap_times[c] == tied:
                if ident[heap_slots[c]] < ident[best]:
                    best = heap_slots[c]
                if found_lo < 0:
                    found_lo = c
                found_hi = c
        if found_lo < 0:
            break
        lo, hi = found_lo, found_hi
    return best


# --- what the engine calls -----------------------------------------------------------------------


@inlined
def earliest(queue, ident) -> int:
    """The slot whose event comes first in the order (time, ident) (``queue``: `views`): the
    heap root's, unless one of its children ties with it (none is earlier), which their least
    tells without a branch each."""
    _, _, heap_times, _, heap_slots, _ = queue
    if heap_times.shape[0] > ARITY:
        tied = least_of_eight(heap_times, 1)[1] == heap_times[0]
    else:
        tied = False
        for c in range(1, heap_times.shape[0]):
            tied |= heap_times[c] == heap_times[0]
    return _earliest_tied(heap_times, heap_slots, ident) if tied else heap_slots[0]


@inlined
def first_time(queue) -> float:
    """The earliest event time in the queue (s)."""
    _, _, heap_times, _, _, _ = queue
    return heap_times[0]


@inlined
def time_of(k, queue) -> float:
    """Slot k's event time (s)."""
    times, _, _, _, _, _ = queue
    return times[k]


@inlined
def update(k, t, queue, ident) -> None:
    """Give slot k the event time t (s), and its block and superblock their earliest
    (``queue``: `views`)."""
    times, block_times, heap_times, block_slots, heap_slots, places = queue
    times[k] = t
    b = k // BLOCK
    held = block_slots[b]
    if k == held:
        when, slot = _block_earliest(b, times, block_slots, ident)
    elif t < block_times[b] or (t == block_times[b] and ident[k] < ident[held]):
        when, slot = t, k
    else:
        return  # the block's earliest is still its earliest
    block_times[b] = when
    block_slots[b] = slot
    s = b // BLOCK
    node = places[s]
    leader = heap_slots[node]
    if leader // BLOCK == b:
        when, slot = _super_earliest(s, block_times, block_slots, ident)
        _heap_update(s, when, slot, heap_times, heap_slots, places)
    elif when < heap_times[node] or (when == heap_times[node] and ident[slot] < ident[leader]):
        _heap_update(s, when, slot, heap_times, heap_slots, places)


@uncounted()
def build(keys, items, ident) -> None:
    """Order the queue from its ``times`` as they lie (the padding slots past ``ident``'s get
    inf): every block's and superblock's earliest, then the heap (O(N))."""
    times, block_times, heap_times, block_slots, heap_slots, places = views(keys, items)
    times[ident.shape[0] :] = math.inf
    for b in range(block_times.shape[0]):
        block_times[b], block_slots[b] = _block_earliest(b, times, block_slots, ident)
    for s in range(heap_times.shape[0]):
        heap_times[s], heap_slots[s] = _super_earliest(s, block_times, block_slots, ident)
        places[s] = s
    for node in range((heap_times.shape[0] - 2) // ARITY, -1, -1):
        _sift_down(node, heap_times[node], heap_slots[node], heap_times, heap_slots, places)


@inlined
def likely_next(queue):
    """The slots whose events most likely come next and after it: the earliest of the heap
    root's children's, and the earliest of that child's children's and its siblings'. A large
    gas's events are so close in time that one predicted meanwhile rarely comes between. The
    heap must be three levels deep."""
    _, _, heap_times, _, heap_slots, _ = queue
    near, _ = least_of_eight(heap_times, 1)
    second, least = least_of_eight(heap_times, ARITY * near + 1)
    for s in range(1, ARITY + 1):
        earlier = s != near and heap_times[s] < least
        least = heap_times[s] if earlier else least
        second = s if earlier else second
    return heap_slots[near], heap_slots[second]


@inlined
def prefetch_lines(k, queue) -> None:
    """Ask for the lines that `update` of slot k reads: its block's times, its superblock's
    block entries and its place in the heap."""
    times, block_times, _, block_slots, _, places = queue
    b = k // BLOCK
    prefetch(times, b * BLOCK)
    prefetch(times, b * BLOCK + BLOCK - 1)
    s = b // BLOCK
    prefetch(block_times, s * BLOCK)
    prefetch(block_times, s * BLOCK + BLOCK - 1)
    prefetch(block_slots, s * BLOCK)
    prefetch(places, s)
