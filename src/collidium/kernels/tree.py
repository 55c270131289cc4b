"""Barnes-Hut quadtree for the softened inverse-distance forces, with order-4 multipoles, walked
per leaf.

Physics as `pairwise.inverse_distance_direct` (open box only): ``F_i = k q_i sum_j q_j r_ij /
(r^2+eps^2)^(3/2)``, energy and virial per particle = half the pair sums of
``k q_i q_j / sqrt(r^2+eps^2)`` and ``r_ij . F_ij``. Written for Coulomb's charges q and
constant k, it sums Newton's gravity as well, with the masses as q and ``-G`` as k.

Tree. Particles are sorted by the Morton (Z-order) code of their cell on a 2^21 x 2^21 grid over
the bounding square (LSD radix sort, ties by index: unique). Each node is the smallest quadtree
cell holding its particles (a compressed quadtree: at most 2N - 1 nodes, every internal node has
2 to 4 children), built breadth first by binary search on the sorted codes; a node with at most
``leaf_size`` particles, or a finest-grid cell, is a leaf. A node stores its particle range, its
children, its geometric centre, a radius bounding its particles' distance from that centre, its
total |q| and its raw moments ``sum q dx^a dy^b``, a + b <= 4, about the centre (leaves from their
particles, internal nodes by binomial translation of their children's).

Expansion. For a kernel ``g(s)`` of ``s = |x|^2`` the Taylor series in the charges' offsets ``d``
from the centre, at offset ``R`` from it, is ``sum_n sum_k (-1)^n / (2^k k! (n-2k)!) D_(n-k)
sum_j q_j |d_j|^2k (d_j . R)^(n-2k)`` with ``D_m = 2^m g^(m)(|R|^2)``: monopole, dipole, the
quadrupole with its trace term, and so on (not traceless: 1/r is a 3D kernel evaluated in a
plane). For the Plummer kernel ``g = (s+eps^2)^(-1/2) = h``, ``D_m = (-1)^m (2m-1)!! h^(2m+1)``,
exact to the order kept; the virial kernel ``s (s+eps^2)^(-3/2) = g + 2 eps^2 g'`` has
``D_m + eps^2 D_(m+1)``, which equals the potential's when eps = 0. Orders n <= 4 (hexadecapole)
are kept, grouped per node into 22 polynomial coefficients (`_coefficients`).

Walk. Each leaf is a group of targets. From the root, a node is accepted when its radius is below
``theta`` times the distance from its centre to the nearest point of the group's bounding box
(so every target sees it at ratio < theta and the error falls like theta^5); opened leaves give
the near field, summed exactly with the softened formula (self skipped, neutral sources skipped
as in the direct sum). The lists are copied into contiguous columns and each target sums over
them in a fixed order, in SIMD. Groups run in parallel; each target is summed by one thread by
the same code, so results are bitwise identical whatever the number of threads. The build (about
4% of the time) runs on one thread, so a call has a single parallel region.

Accuracy and cost, leaf size 64, for a neutral gas: N charges +1/-1 alternating, uniform in a
200 m square (N/40000 per m^2), k = 5. Error: RMS relative force error
``sqrt(mean_i |F_i - F_direct_i|^2 / |F_direct_i|^2)`` on 2000 random targets; "typical" is the
median over 8 gases of N = 1e5 (eps = 0; eps = 0.05 gives the same), "worst" the largest over
N = 1e3, 1e4, 1e5, 1e6, eps = 0 and 0.05, and a 100 times denser gas. This metric is dominated
by the rare particles whose total force nearly cancels, hence the spread. Time: one evaluation,
tree build included, N = 1e6, one thread of an AMD Zen 5 (AVX-512), best of repeated runs on a
shared machine, microseconds per particle:

=====  =========  =======  ===========
theta  typical    worst    us/particle
=====  =========  =======  ===========
0.2    4.4e-6     3.0e-5   1.96
0.25   1.8e-5     9.0e-5   1.42
0.3    5.0e-5     3.0e-4   1.10
0.35   1.2e-4     3.5e-4   0.91
0.4    3.2e-4     2.2e-3   0.77
0.5    6.6e-4     3.7e-3   0.53
=====  =========  =======  ===========

The default THETA = 0.3 keeps the error below 1e-3 with a margin of 3 in the worst case seen
and 20 typically; with eps larger than the interparticle spacing (forces then collective
and weak) errors are 5 to 7 times the eps = 0 ones. Two threads take 0.31, 0.40 and 0.59
us/particle at N = 1e4, 1e5 and 1e6 (one thread: 0.58, 0.76, 1.12). The tree beats
`inverse_distance_direct` (2 threads) from about N = 200 (0.15 against 0.23 us/particle at
N = 500, 0.21 against 0.85 at N = 2000).

Use: ``buffers = tree_buffers(n)`` once, then ``inverse_distance_tree(position, charge, k,
eps**2, force, energy, virial, buffers)`` each step; or the kernels `build_tree` and
`evaluate_tree` directly.
Not for periodic boxes (no images).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels.pairwise import inverse_distance_pair, larger
from collidium.kernels.sorting import radix_sort

THETA = 0.3
"""Default opening angle: a node is used as an expansion when its radius is below THETA times its
distance from the group of targets (see the module docstring for the measured errors)."""

LEAF_SIZE = 64
"""Default largest particle count of a leaf (about half that on average in a uniform gas). Among
16 to 128, 64 gave the lowest time at equal error: larger leaves move work to the near field,
which is exact and cheap per pair, and lower the error at a given theta."""

RMS_FORCE_ERROR = {0.2: 4.4e-6, 0.25: 1.8e-5, 0.3: 5.0e-5, 0.35: 1.2e-4, 0.4: 3.2e-4, 0.5: 6.6e-4}
"""Typical RMS relative force error per opening angle (leaf size 64, neutral gas, N = 1e5),
as measured for the module docstring's table; single systems reached up to 6 times more."""

BITS = 21
"""Bits of the Morton code per axis: cells down to 2**-21 of the root square; particles closer
than that share a leaf whatever their number."""

N_RAW = 15
"""Raw moments ``sum q dx^a dy^b`` with a + b <= 4 (order 4, hexadecapole), stored by degree
``n = a + b`` then b: index ``n (n + 1) / 2 + b``."""

N_COEF = 22
"""Polynomial coefficients per node read by the far-field evaluation (see `_coefficients`)."""

_BINOMIAL = np.array(
    [[1, 0, 0, 0, 0], [1, 1, 0, 0, 0], [1, 2, 1, 0, 0], [1, 3, 3, 1, 0], [1, 4, 6, 4, 1]],
    dtype=np.float64,
)


# --------------------------------------------------------------------------------------------
# Morton order
# --------------------------------------------------------------------------------------------


@numba.njit(cache=True, inline="always")
def _spread_bits(v: int) -> int:
    """Put bit b of a 21-bit integer at bit 2b (zeros between)."""
    v = (v | (v << 16)) & 0x0000FFFF0000FFFF
    v = (v | (v << 8)) & 0x00FF00FF00FF00FF
    v = (v | (v << 4)) & 0x0F0F0F0F0F0F0F0F
    v = (v | (v << 2)) & 0x3333333333333333
    return (v | (v << 1)) & 0x5555555555555555


@numba.njit(cache=True, inline="always")
def _compact_bits(v: int) -> int:
    """Inverse of `_spread_bits`: gather the even bits of ``v``."""
    v &= 0x5555555555555555
    v = (v | (v >> 1)) & 0x3333333333333333
    v = (v | (v >> 2)) & 0x0F0F0F0F0F0F0F0F
    v = (v | (v >> 4)) & 0x00FF00FF00FF00FF
    v = (v | (v >> 8)) & 0x0000FFFF0000FFFF
    return (v | (v >> 16)) & 0x00000000FFFFFFFF


@numba.njit(cache=True)
def _bounding_square(position: np.ndarray) -> tuple[float, float, float]:
    """Lower-left corner (m) and side (m) of the square root cell holding every particle."""
    n = position.shape[0]
    x_lo = position[0, 0]
    x_hi = x_lo
    y_lo = position[0, 1]
    y_hi = y_lo
    for i in range(1, n):
        x_lo = min(x_lo, position[i, 0])
        x_hi = max(x_hi, position[i, 0])
        y_lo = min(y_lo, position[i, 1])
        y_hi = max(y_hi, position[i, 1])
    side = max(x_hi - x_lo, y_hi - y_lo)
    if side <= 0.0:
        side = 1.0  # all particles coincide: any cell size will do
    return x_lo, y_lo, side


@numba.njit(cache=True)
def _morton_codes(
    position: np.ndarray, x_lo: float, y_lo: float, side: float, code: np.ndarray
) -> None:
    """Z-order code of each particle's cell on the finest (2**BITS per side) grid."""
    cells = 1 << BITS
    scale = cells / side
    for i in range(position.shape[0]):
        ix = min(max(int((position[i, 0] - x_lo) * scale), 0), cells - 1)
        iy = min(max(int((position[i, 1] - y_lo) * scale), 0), cells - 1)
        code[i] = _spread_bits(ix) | (_spread_bits(iy) << 1)


@numba.njit(cache=True)
def _gather_sorted(
    position: np.ndarray,
    charge: np.ndarray,
    order: np.ndarray,
    sorted_x: np.ndarray,
    sorted_y: np.ndarray,
    sorted_q: np.ndarray,
) -> None:
    """Copy positions and charges into Morton order, one array per component (for SIMD)."""
    for i in range(order.shape[0]):
        j = order[i]
        sorted_x[i] = position[j, 0]
        sorted_y[i] = position[j, 1]
        sorted_q[i] = charge[j]


# --------------------------------------------------------------------------------------------
# Tree topology
# --------------------------------------------------------------------------------------------


@numba.njit(cache=True, inline="always")
def _common_level(first: int, last: int) -> int:
    """Depth of the smallest quadtree cell holding both codes (0: root, BITS: finest)."""
    differ = first ^ last
    level = BITS
    while differ != 0:
        differ >>= 2
        level -= 1
    return level


@numba.njit(cache=True, inline="always")
def _first_with_digit(key: np.ndarray, lo: int, hi: int, shift: int, digit: int) -> int:
    """First index in ``[lo, hi)`` whose 2-bit digit at ``shift`` is >= ``digit`` (digits are
    non-decreasing there because the range shares every coarser digit)."""
    while lo < hi:
        mid = (lo + hi) >> 1
        if (key[mid] >> shift) & 3 < digit:
            lo = mid + 1
        else:
            hi = mid
    return lo


@numba.njit(cache=True)
def _split_nodes(
    key: np.ndarray, leaf_size: int, node_index: np.ndarray, depth_start: np.ndarray
) -> tuple[int, int]:
    """Build the compressed quadtree topology breadth first over Morton-sorted codes.

    Each node is the smallest quadtree cell holding its particles, so every internal node has at
    least two children and there are at most ``2 N - 1`` nodes. Nodes of equal depth are
    contiguous (``depth_start``), children of a node contiguous and after it.

    Parameters
    ----------
    key : ndarray of int64, shape (N,)
        Sorted Morton codes.
    leaf_size : int
        Largest particle count of a leaf (cells at depth BITS may hold more).
    node_index : ndarray of int64, shape (capacity, 5)
        Output per node: first particle, end particle (sorted order), first child (-1 for a
        leaf), number of children, quadtree level of the cell.
    depth_start : ndarray of int64, shape (BITS + 3,)
        Output: first node of each depth; entry ``depths`` is the node count.

    Returns
    -------
    tuple of int
        ``(nodes, depths)``, or ``(-1, 0)`` if ``capacity`` is too small.
    """
    n = key.shape[0]
    capacity = node_index.shape[0]
    node_index[0, 0] = 0
    node_index[0, 1] = n
    nodes = 1
    lo = 0
    hi = 1
    depth = 0
    depth_start[0] = 0
    while lo < hi:
        for i in range(lo, hi):
            start = node_index[i, 0]
            end = node_index[i, 1]
            level = _common_level(key[start], key[end - 1])
            node_index[i, 4] = level
            node_index[i, 2] = -1
            node_index[i, 3] = 0
            if end - start <= leaf_size or level == BITS:
                continue
            shift = 2 * (BITS - level - 1)
            node_index[i, 2] = nodes
            first = start
            for digit in range(1, 5):
                last = end if digit == 4 else _first_with_digit(key, first, end, shift, digit)
                if last > first:
                    if nodes == capacity:
                        return -1, 0
                    node_index[nodes, 0] = first
                    node_index[nodes, 1] = last
                    nodes += 1
                    node_index[i, 3] += 1
                first = last
        depth += 1
        depth_start[depth] = hi
        lo = hi
        hi = nodes
    return nodes, depth


@numba.njit(cache=True)
def _leaves_in_morton_order(node_index: np.ndarray, leaves: np.ndarray) -> int:
    """Depth-first walk listing the leaves in particle order; returns their count."""
    stack = np.empty(4 * (BITS + 2), dtype=np.int64)
    stack[0] = 0
    top = 1
    count = 0
    while top > 0:
        top -= 1
        node = stack[top]
        first = node_index[node, 2]
        if first < 0:
            leaves[count] = node
            count += 1
            continue
        for c in range(node_index[node, 3] - 1, -1, -1):  # reversed: popped in order
            stack[top] = first + c
            top += 1
    return count


# --------------------------------------------------------------------------------------------
# Multipole moments
# --------------------------------------------------------------------------------------------


@numba.njit(cache=True, inline="always")
def _cell_centre(
    first_key: int, level: int, x_lo: float, y_lo: float, side: float
) -> tuple[float, float, float]:
    """Centre (m) and half side (m) of the level-``level`` cell holding ``first_key``."""
    drop = 2 * (BITS - level)
    ix = _compact_bits(first_key >> drop)
    iy = _compact_bits(first_key >> (drop + 1))
    cell = side / (1 << level)
    return x_lo + (ix + 0.5) * cell, y_lo + (iy + 0.5) * cell, 0.5 * cell


@numba.njit(cache=True)
def _leaf_moments(
    sorted_x: np.ndarray,
    sorted_y: np.ndarray,
    sorted_q: np.ndarray,
    key: np.ndarray,
    x_lo: float,
    y_lo: float,
    side: float,
    node_index: np.ndarray,
    leaves: np.ndarray,
    n_leaves: int,
    node_geometry: np.ndarray,
    node_raw: np.ndarray,
) -> None:
    """Raw moments ``sum q dx^a dy^b`` (a + b <= 4) of each leaf about its cell centre, its
    radius (largest particle distance from the centre) and its total |q|."""
    for t in range(n_leaves):
        node = leaves[t]
        start = node_index[node, 0]
        end = node_index[node, 1]
        cx, cy, _ = _cell_centre(key[start], node_index[node, 4], x_lo, y_lo, side)
        raw = node_raw[node]
        raw[:] = 0.0
        radius2 = 0.0
        charge_abs = 0.0
        for i in range(start, end):
            q = sorted_q[i]
            dx = sorted_x[i] - cx
            dy = sorted_y[i] - cy
            radius2 = max(radius2, dx * dx + dy * dy)
            charge_abs += abs(q)
            qx = q * dx
            qxx = qx * dx
            qxxx = qxx * dx
            dy2 = dy * dy
            raw[0] += q
            raw[1] += qx
            raw[2] += q * dy
            raw[3] += qxx
            raw[4] += qx * dy
            raw[5] += q * dy2
            raw[6] += qxxx
            raw[7] += qxx * dy
            raw[8] += qx * dy2
            raw[9] += q * dy2 * dy
            raw[10] += qxxx * dx
            raw[11] += qxxx * dy
            raw[12] += qxx * dy2
            raw[13] += qx * dy2 * dy
            raw[14] += q * dy2 * dy2
        node_geometry[node, 0] = cx
        node_geometry[node, 1] = cy
        node_geometry[node, 2] = math.sqrt(radius2)
        node_geometry[node, 3] = charge_abs


@numba.njit(cache=True)
def _shift_moments(raw_child: np.ndarray, ox: float, oy: float, raw: np.ndarray) -> None:
    """Add a child's raw moments, re-expressed about a centre displaced by ``-(ox, oy)``, to
    ``raw`` (M2M): ``sum q (dx + ox)^a (dy + oy)^b`` expanded by the binomial theorem."""
    power_x = (1.0, ox, ox * ox, ox * ox * ox, ox * ox * ox * ox)
    power_y = (1.0, oy, oy * oy, oy * oy * oy, oy * oy * oy * oy)
    for degree in range(5):
        for b in range(degree + 1):
            a = degree - b
            total = 0.0
            for i in range(a + 1):
                for j in range(b + 1):
                    total += (
                        _BINOMIAL[a, i]
                        * _BINOMIAL[b, j]
                        * power_x[a - i]
                        * power_y[b - j]
                        * raw_child[(i + j) * (i + j + 1) // 2 + j]
                    )
            raw[degree * (degree + 1) // 2 + b] += total


@numba.njit(cache=True)
def _internal_moments(
    key: np.ndarray,
    x_lo: float,
    y_lo: float,
    side: float,
    node_index: np.ndarray,
    depth_start: np.ndarray,
    depths: int,
    node_geometry: np.ndarray,
    node_raw: np.ndarray,
) -> None:
    """Moments of internal nodes from their children's, deepest level first (M2M). The radius
    is bounded by ``max(|offset| + child radius)``."""
    for depth in range(depths - 1, -1, -1):
        for node in range(depth_start[depth], depth_start[depth + 1]):
            first = node_index[node, 2]
            if first < 0:
                continue
            start = node_index[node, 0]
            cx, cy, half = _cell_centre(key[start], node_index[node, 4], x_lo, y_lo, side)
            raw = node_raw[node]
            raw[:] = 0.0
            radius = 0.0
            charge_abs = 0.0
            for child in range(first, first + node_index[node, 3]):
                ox = node_geometry[child, 0] - cx
                oy = node_geometry[child, 1] - cy
                _shift_moments(node_raw[child], ox, oy, raw)
                radius = max(radius, math.sqrt(ox * ox + oy * oy) + node_geometry[child, 2])
                charge_abs += node_geometry[child, 3]
            node_geometry[node, 0] = cx
            node_geometry[node, 1] = cy
            node_geometry[node, 2] = min(radius, math.sqrt(2.0) * half)
            node_geometry[node, 3] = charge_abs


@numba.njit(cache=True)
def _coefficients(node_raw: np.ndarray, nodes: int, node_coef: np.ndarray) -> None:
    """Polynomial coefficients of the far field of each node from its raw moments.

    With ``R`` the target's offset from the node centre, ``h = (|R|^2 + eps^2)^(-1/2)`` and
    ``B_m(R)`` polynomials of degree <= m, the potential per unit target charge (over k) is
    ``Phi = sum_m h^(2m+1) B_m``: the Taylor expansion of ``sum_j q_j g(|R - d_j|^2)`` with
    ``g(s) = (s + eps^2)^(-1/2)``, grouped by the derivative of g that multiplies each term
    (``2^m g^(m) = (-1)^m (2m-1)!! h^(2m+1)``). Row layout (monomials in X, Y):

    ``B_0 = c0``; ``B_1 = c1 X + c2 Y + c3``;
    ``B_2 = c4 X^2 + c5 XY + c6 Y^2 + c7 X + c8 Y + c9``;
    ``B_3 = c10 X^3 + c11 X^2 Y + c12 X Y^2 + c13 Y^3 + c14 X^2 + c15 XY + c16 Y^2``;
    ``B_4 = c17 X^4 + c18 X^3 Y + c19 X^2 Y^2 + c20 X Y^3 + c21 Y^4``.
    """
    for node in range(nodes):
        m = node_raw[node]
        c = node_coef[node]
        q = m[0]
        px, py = m[1], m[2]
        mxx, mxy, myy = m[3], m[4], m[5]
        oxxx, oxxy, oxyy, oyyy = m[6], m[7], m[8], m[9]
        hxxxx, hxxxy, hxxyy, hxyyy, hyyyy = m[10], m[11], m[12], m[13], m[14]
        # Traces of the moment tensors: sum q |d|^2, sum q |d|^2 d, sum q |d|^4, sum q |d|^2 dd.
        trace2 = mxx + myy
        trace3x = oxxx + oxyy
        trace3y = oxxy + oyyy
        trace4 = hxxxx + 2.0 * hxxyy + hyyyy
        trace4xx = hxxxx + hxxyy
        trace4xy = hxxxy + hxyyy
        trace4yy = hxxyy + hyyyy
        # m = 0: monopole.
        c[0] = q
        # m = 1: -(dipole term - trace/2), sign (-1)^1 and 1!! folded in.
        c[1] = px
        c[2] = py
        c[3] = -0.5 * trace2
        # m = 2: 3 * (M[R,R]/2 - trace3.R/2 + trace4/8).
        c[4] = 1.5 * mxx
        c[5] = 3.0 * mxy
        c[6] = 1.5 * myy
        c[7] = -1.5 * trace3x
        c[8] = -1.5 * trace3y
        c[9] = 0.375 * trace4
        # m = 3: -15 * (-O[R,R,R]/6 + trace4[R,R]/4).
        c[10] = 2.5 * oxxx
        c[11] = 7.5 * oxxy
        c[12] = 7.5 * oxyy
        c[13] = 2.5 * oyyy
        c[14] = -3.75 * trace4xx
        c[15] = -7.5 * trace4xy
        c[16] = -3.75 * trace4yy
        # m = 4: 105 * H[R,R,R,R]/24.
        c[17] = 4.375 * hxxxx
        c[18] = 17.5 * hxxxy
        c[19] = 26.25 * hxxyy
        c[20] = 17.5 * hxyyy
        c[21] = 4.375 * hyyyy


# --------------------------------------------------------------------------------------------
# Evaluation
# --------------------------------------------------------------------------------------------

# Reductions over a group's source lists vectorise only if the adds may be reassociated. Each
# target is still summed by the same instructions in the same order whatever the thread count.
_FAST = {"reassoc", "contract"}

_FAR_ROWS = N_COEF + 2
"""Rows of a group's far list: the node's coefficients, then its centre x and y."""


@numba.njit(cache=True, fastmath=_FAST, error_model="numpy")
def _near_sum(
    x: float,
    y: float,
    target: int,
    source: np.ndarray,
    source_index: np.ndarray,
    count: int,
    softening2: float,
) -> tuple[float, float, float, float]:
    """Exact softened pair terms on one target from ``count`` sources (rows x, y, q of
    ``source``), per unit target charge and over k; the target itself is skipped by index.

    Returns
    -------
    tuple of float
        Field x, y (``sum q r / (r^2+eps^2)^(3/2)``), potential (``sum q / sqrt(r^2+eps^2)``)
        and virial sum (``sum q r^2 / (r^2+eps^2)^(3/2)``).
    """
    sx = source[0]
    sy = source[1]
    sq = source[2]
    ex = 0.0
    ey = 0.0
    phi = 0.0
    w = 0.0
    for j in range(count):
        dx = x - sx[j]
        dy = y - sy[j]
        r2 = dx * dx + dy * dy
        itself = source_index[j] == target  # skipped with a zero charge at a harmless distance
        f, u = inverse_distance_pair(1.0 if itself else r2, 0.0 if itself else sq[j], softening2)
        ex += f * dx
        ey += f * dy
        phi += u
        w += f * r2
    return ex, ey, phi, w


@numba.njit(cache=True, fastmath=_FAST, error_model="numpy")
def _far_sum(
    x: float, y: float, far: np.ndarray, count: int, softening2: float
) -> tuple[float, float, float, float]:
    """Multipole expansions of ``count`` nodes (columns of ``far``) on one target at (x, y).

    With ``R`` the offset from a node's centre and ``h = (|R|^2 + eps^2)^(-1/2)``, the potential
    is ``Phi = sum_m h^(2m+1) B_m(R)`` (see `_coefficients`), its gradient
    ``R S1 + sum_m h^(2m+1) grad B_m`` with ``S1 = -sum_m (2m+1) h^(2m+3) B_m``, and the virial
    kernel ``s (s+eps^2)^(-3/2) = g + 2 eps^2 g'`` expands to ``Phi + eps^2 S1``.

    Returns
    -------
    tuple of float
        Field x, y (``-grad Phi``), potential and virial sum, per unit charge and over k.
    """
    ex = 0.0
    ey = 0.0
    phi_sum = 0.0
    w = 0.0
    cx = far[N_COEF]
    cy = far[N_COEF + 1]
    for n in range(count):
        c0, c1, c2, c3 = far[0, n], far[1, n], far[2, n], far[3, n]
        c4, c5, c6, c7, c8, c9 = far[4, n], far[5, n], far[6, n], far[7, n], far[8, n], far[9, n]
        c10, c11, c12, c13 = far[10, n], far[11, n], far[12, n], far[13, n]
        c14, c15, c16 = far[14, n], far[15, n], far[16, n]
        c17, c18, c19, c20, c21 = far[17, n], far[18, n], far[19, n], far[20, n], far[21, n]
        rx = x - cx[n]
        ry = y - cy[n]
        xx = rx * rx
        xy = rx * ry
        yy = ry * ry
        h = 1.0 / math.sqrt(xx + yy + softening2)
        h2 = h * h
        b1 = c1 * rx + c2 * ry + c3
        b2 = c4 * xx + c5 * xy + c6 * yy + c7 * rx + c8 * ry + c9
        b3 = (c10 * rx + c11 * ry + c14) * xx + (c12 * rx + c13 * ry + c16) * yy + c15 * xy
        b4 = (c17 * xx + c18 * xy + c19 * yy) * xx + (c20 * xy + c21 * yy) * yy
        g2x = 2.0 * c4 * rx + c5 * ry + c7
        g2y = c5 * rx + 2.0 * c6 * ry + c8
        g3x = (3.0 * c10 * rx + 2.0 * c11 * ry + 2.0 * c14) * rx + (c12 * ry + c15) * ry
        g3y = (c11 * rx + c15) * rx + (2.0 * c12 * rx + 3.0 * c13 * ry + 2.0 * c16) * ry
        g4x = (4.0 * c17 * xx + 3.0 * c18 * xy + 2.0 * c19 * yy) * rx + c20 * yy * ry
        g4y = c18 * xx * rx + (2.0 * c19 * xx + 3.0 * c20 * xy + 4.0 * c21 * yy) * ry
        h3 = h * h2
        phi = h * (c0 + h2 * (b1 + h2 * (b2 + h2 * (b3 + h2 * b4))))
        s1 = -h3 * (c0 + h2 * (3.0 * b1 + h2 * (5.0 * b2 + h2 * (7.0 * b3 + h2 * 9.0 * b4))))
        ex -= rx * s1 + h3 * (c1 + h2 * (g2x + h2 * (g3x + h2 * g4x)))
        ey -= ry * s1 + h3 * (c2 + h2 * (g2y + h2 * (g3y + h2 * g4y)))
        phi_sum += phi
        w += phi + softening2 * s1
    return ex, ey, phi_sum, w


@numba.njit(cache=True)
def _interaction_lists(
    sorted_x: np.ndarray,
    sorted_y: np.ndarray,
    start: int,
    end: int,
    theta: float,
    node_index: np.ndarray,
    node_geometry: np.ndarray,
    stack: np.ndarray,
    far: np.ndarray,
    near: np.ndarray,
) -> tuple[int, int, int]:
    """Walk the tree for the group of targets ``[start, end)`` (sorted order).

    A node is accepted (far list) when its radius is below ``theta`` times the distance from its
    centre to the nearest point of the group's bounding box, so the expansion converges at least
    as fast as ``theta^5`` for every target of the group. Opened leaves go to the near list as
    particle ranges (adjacent ranges merged). Nodes without charge are dropped.

    Returns
    -------
    tuple of int
        Lengths of ``far`` (node ids) and ``near`` (rows ``(first, end)``) and the number of
        particles in the near ranges; ``(-1, 0, 0)`` if ``far`` or ``near`` is too short.
    """
    x_lo = sorted_x[start]
    x_hi = x_lo
    y_lo = sorted_y[start]
    y_hi = y_lo
    for i in range(start + 1, end):
        x_lo = min(x_lo, sorted_x[i])
        x_hi = max(x_hi, sorted_x[i])
        y_lo = min(y_lo, sorted_y[i])
        y_hi = max(y_hi, sorted_y[i])
    theta2 = theta * theta
    n_far = 0
    n_near = 0
    n_particles = 0
    stack[0] = 0
    top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        if node_geometry[node, 3] == 0.0:
            continue
        cx = node_geometry[node, 0]
        cy = node_geometry[node, 1]
        radius = node_geometry[node, 2]
        gap_x = max(x_lo - cx, 0.0, cx - x_hi)
        gap_y = max(y_lo - cy, 0.0, cy - y_hi)
        if radius * radius < theta2 * (gap_x * gap_x + gap_y * gap_y):
            if n_far == far.shape[0]:
                return -1, 0, 0
            far[n_far] = node
            n_far += 1
            continue
        first = node_index[node, 2]
        if first < 0:
            n_particles += node_index[node, 1] - node_index[node, 0]
            if n_near > 0 and near[n_near - 1, 1] == node_index[node, 0]:
                near[n_near - 1, 1] = node_index[node, 1]
                continue
            if n_near == near.shape[0]:
                return -1, 0, 0
            near[n_near, 0] = node_index[node, 0]
            near[n_near, 1] = node_index[node, 1]
            n_near += 1
            continue
        for c in range(node_index[node, 3] - 1, -1, -1):  # reversed: popped in Morton order
            stack[top] = first + c
            top += 1
    return n_far, n_near, n_particles


@numba.njit(cache=True)
def _gather_sources(
    sorted_x: np.ndarray,
    sorted_y: np.ndarray,
    sorted_q: np.ndarray,
    near: np.ndarray,
    n_near: int,
    source: np.ndarray,
    source_index: np.ndarray,
) -> int:
    """Copy the charged particles of the near ranges into contiguous rows x, y, q of ``source``
    (their sorted indices into ``source_index``); returns their count. Neutral particles are
    left out, as in the direct sum (no ``0 * inf`` from one sitting on a target)."""
    count = 0
    for r in range(n_near):
        for j in range(near[r, 0], near[r, 1]):
            if sorted_q[j] != 0.0:
                source[0, count] = sorted_x[j]
                source[1, count] = sorted_y[j]
                source[2, count] = sorted_q[j]
                source_index[count] = j
                count += 1
    return count


@numba.njit(cache=True)
def _gather_far(
    far: np.ndarray,
    n_far: int,
    node_geometry: np.ndarray,
    node_coef: np.ndarray,
    far_data: np.ndarray,
) -> None:
    """Copy the accepted nodes' coefficients and centres into columns of ``far_data``."""
    for r in range(n_far):
        node = far[r]
        for c in range(N_COEF):
            far_data[c, r] = node_coef[node, c]
        far_data[N_COEF, r] = node_geometry[node, 0]
        far_data[N_COEF + 1, r] = node_geometry[node, 1]


@numba.njit(cache=True, parallel=True)
def evaluate_tree(
    k: float,
    softening2: float,
    theta: float,
    order: np.ndarray,
    sorted_x: np.ndarray,
    sorted_y: np.ndarray,
    sorted_q: np.ndarray,
    node_index: np.ndarray,
    node_geometry: np.ndarray,
    node_coef: np.ndarray,
    leaves: np.ndarray,
    n_leaves: int,
    force: np.ndarray,
    energy: np.ndarray,
    virial: np.ndarray,
) -> None:
    """Coulomb forces, per-particle energies and virials from a tree made by `build_tree`.

    Each leaf is one group: its interaction lists are copied into contiguous columns, then each
    of its targets sums over them, near field then far field, and gets ``k q_i`` times the sums
    (exact zeros for a neutral particle, as in the direct sum). Groups are split into a fixed
    number of contiguous chunks run in parallel (with their own growing scratch arrays), so
    every target is summed by one thread, by the same instructions, in the same order. This is
    the only parallel loop of a call: under oversubscribed cores each parallel region can cost a
    time slice, and the build is cheap enough to run on one thread.

    Parameters
    ----------
    k : float
        Coulomb constant in N m^2 / C^2.
    softening2 : float
        Squared softening length in m^2.
    theta : float
        Opening angle (0 opens every node: direct summation).
    order, sorted_x, sorted_y, sorted_q, node_index, node_geometry, node_coef, leaves : ndarray
        As filled by `build_tree`; ``n_leaves`` its second return value.
    force : ndarray, shape (N, 2)
        Output: total force on each particle, N.
    energy : ndarray, shape (N,)
        Output: half the pair energy of each particle with all others, J.
    virial : ndarray, shape (N,)
        Output: half of ``sum_j r_ij . F_ij`` for each particle, J.
    """
    chunks = min(n_leaves, 256)
    for chunk in numba.prange(chunks):
        stack = np.empty(4 * (BITS + 2), dtype=np.int64)
        far = np.empty(256, dtype=np.int64)
        near = np.empty((64, 2), dtype=np.int64)
        far_data = np.empty((_FAR_ROWS, 256))
        source = np.empty((3, 1024))
        source_index = np.empty(1024, dtype=np.int64)
        for t in range(chunk * n_leaves // chunks, (chunk + 1) * n_leaves // chunks):
            leaf = leaves[t]
            start = node_index[leaf, 0]
            end = node_index[leaf, 1]
            while True:
                n_far, n_near, n_particles = _interaction_lists(
                    sorted_x, sorted_y, start, end, theta, node_index, node_geometry, stack,
                    far, near,
                )  # fmt: skip
                if n_far >= 0:
                    break
                far = np.empty(2 * far.shape[0], dtype=np.int64)
                near = np.empty((2 * near.shape[0], 2), dtype=np.int64)
            if n_far > far_data.shape[1]:
                far_data = np.empty((_FAR_ROWS, 2 * n_far))
            _gather_far(far, n_far, node_geometry, node_coef, far_data)
            if n_particles > source.shape[1]:
                source = np.empty((3, 2 * n_particles))
                source_index = np.empty(2 * n_particles, dtype=np.int64)
            count = _gather_sources(
                sorted_x, sorted_y, sorted_q, near, n_near, source, source_index
            )
            for i in range(start, end):
                j = order[i]
                kq = k * sorted_q[i]
                if kq == 0.0:
                    force[j, 0] = 0.0
                    force[j, 1] = 0.0
                    energy[j] = 0.0
                    virial[j] = 0.0
                    continue
                x = sorted_x[i]
                y = sorted_y[i]
                ex, ey, phi, w = _near_sum(x, y, i, source, source_index, count, softening2)
                fx, fy, far_phi, far_w = _far_sum(x, y, far_data, n_far, softening2)
                force[j, 0] = kq * (ex + fx)
                force[j, 1] = kq * (ey + fy)
                energy[j] = 0.5 * kq * (phi + far_phi)
                virial[j] = 0.5 * kq * (w + far_w)


@numba.njit(cache=True)
def acceleration_stiffness(
    velocity: np.ndarray,
    acceleration: np.ndarray,
    mass: np.ndarray,
    radius: np.ndarray,
    softening: float,
    spacing: float,
) -> float:
    """The largest ``(|U_i| rate_i^2)^2`` (J^2/s^4) over particles, estimated from each one's
    acceleration, for a pair force summed by tree (which has no pair list to take it from).

    ``l_i`` is the particle's diameter or ``softening``, whichever is larger, or ``spacing``
    when both are 0; ``|U_i| = m_i |a_i| l_i`` and ``rate_i^2 = (|v_i|^2 / l_i + |a_i|) / l_i``.

    Parameters
    ----------
    velocity, acceleration : ndarray, shape (N, 2)
        In m/s and m/s^2 (of all forces).
    mass, radius : ndarray, shape (N,)
        In kg and m.
    softening, spacing : float
        The softening length and the mean spacing of the particles, m.
    """
    largest = 0.0
    for i in range(velocity.shape[0]):
        length = max(2.0 * radius[i], softening)
        if not length > 0.0:
            length = spacing
        pull = math.sqrt(acceleration[i, 0] ** 2 + acceleration[i, 1] ** 2)
        speed2 = velocity[i, 0] * velocity[i, 0] + velocity[i, 1] * velocity[i, 1]
        error = mass[i] * pull * (speed2 / length + pull)
        largest = larger(largest, error * error)
    return largest


# --------------------------------------------------------------------------------------------
# Public kernels and driver
# --------------------------------------------------------------------------------------------


@numba.njit(cache=True)
def build_tree(
    position: np.ndarray,
    charge: np.ndarray,
    leaf_size: int,
    code: np.ndarray,
    key: np.ndarray,
    key_spare: np.ndarray,
    order: np.ndarray,
    order_spare: np.ndarray,
    sorted_x: np.ndarray,
    sorted_y: np.ndarray,
    sorted_q: np.ndarray,
    node_index: np.ndarray,
    node_geometry: np.ndarray,
    node_raw: np.ndarray,
    node_coef: np.ndarray,
    leaves: np.ndarray,
    depth_start: np.ndarray,
) -> tuple[int, int]:
    """Sort the particles in Morton order and build the quadtree with its expansions.

    Parameters
    ----------
    position : ndarray, shape (N, 2)
        Centres in m, N >= 1.
    charge : ndarray, shape (N,)
        Charges in C.
    leaf_size : int
        Largest particle count of a leaf (except cells at depth BITS).
    code, key, key_spare, order, order_spare : ndarray of int64, shape (N,)
        Work arrays; on return ``order`` lists the particles in Morton order and ``key`` holds
        their codes.
    sorted_x, sorted_y, sorted_q : ndarray, shape (N,)
        Output: positions (m) and charges (C) in Morton order.
    node_index : ndarray of int64, shape (capacity, 5)
        Output per node: first and end particle (sorted order), first child (-1 for a leaf),
        number of children, quadtree level.
    node_geometry : ndarray, shape (capacity, 4)
        Output per node: centre x, y (m), radius (m, bound on the particles' distance from the
        centre), total |q| (C).
    node_raw : ndarray, shape (capacity, N_RAW)
        Output: raw moments about the centre (C m^(a+b)).
    node_coef : ndarray, shape (capacity, N_COEF)
        Output: far-field coefficients (see `_coefficients`).
    leaves : ndarray of int64, shape (capacity,)
        Output: the leaves in Morton order.
    depth_start : ndarray of int64, shape (BITS + 3,)
        Output: first node of each depth.

    Returns
    -------
    tuple of int
        ``(nodes, leaves)``, or ``(-1, 0)`` when ``capacity`` is too small (grow the node arrays
        and call again).
    """
    x_lo, y_lo, side = _bounding_square(position)
    _morton_codes(position, x_lo, y_lo, side, code)
    for i in range(code.shape[0]):  # from index order, so ties resolve by index
        key[i] = code[i]
        order[i] = i
    radix_sort(key, key_spare, 2 * BITS, order, order_spare)
    _gather_sorted(position, charge, order, sorted_x, sorted_y, sorted_q)
    nodes, depths = _split_nodes(key, leaf_size, node_index, depth_start)
    if nodes < 0:
        return -1, 0
    n_leaves = _leaves_in_morton_order(node_index, leaves)
    _leaf_moments(
        sorted_x, sorted_y, sorted_q, key, x_lo, y_lo, side, node_index, leaves, n_leaves,
        node_geometry, node_raw,
    )  # fmt: skip
    _internal_moments(
        key, x_lo, y_lo, side, node_index, depth_start, depths, node_geometry, node_raw
    )
    _coefficients(node_raw, nodes, node_coef)
    return nodes, n_leaves


_INDEX_ARRAYS = ("code", "key", "key_spare", "order", "order_spare")
_REAL_ARRAYS = ("sorted_x", "sorted_y", "sorted_q")


def _node_arrays(capacity: int) -> dict[str, np.ndarray]:
    """Per-node arrays for ``capacity`` nodes."""
    return {
        "node_index": np.empty((capacity, 5), dtype=np.int64),
        "node_geometry": np.empty((capacity, 4)),
        "node_raw": np.empty((capacity, N_RAW)),
        "node_coef": np.empty((capacity, N_COEF)),
        "leaves": np.empty(capacity, dtype=np.int64),
    }


def tree_buffers(n: int, leaf_size: int = LEAF_SIZE) -> dict[str, np.ndarray]:
    """Work arrays for `inverse_distance_tree` with ``n`` particles, to allocate once and keep.

    The node arrays start at a capacity that fits uniform and moderately clustered systems;
    `inverse_distance_tree` doubles them in place in the dict if a tree ever needs more (at most
    ``2 n - 1`` nodes).

    Returns
    -------
    dict of str to ndarray
        About ``(8 + 376 / leaf_size) * 8`` bytes per particle (111 bytes for 64).
    """
    arrays: dict[str, np.ndarray] = {name: np.empty(n, dtype=np.int64) for name in _INDEX_ARRAYS}
    arrays.update({name: np.empty(n) for name in _REAL_ARRAYS})
    arrays.update(_node_arrays(min(max(2 * n - 1, 1), 8 * n // max(leaf_size, 1) + 64)))
    arrays["depth_start"] = np.empty(BITS + 3, dtype=np.int64)
    return arrays


def inverse_distance_tree(
    position: np.ndarray,
    source: np.ndarray,
    coupling: float,
    softening2: float,
    force: np.ndarray,
    energy: np.ndarray,
    virial: np.ndarray,
    buffers: dict[str, np.ndarray],
    theta: float = THETA,
    leaf_size: int = LEAF_SIZE,
) -> None:
    """Inverse-distance forces, per-particle energies and virials by Barnes-Hut tree, O(N log N).

    Same physics, outputs and units as `pairwise.inverse_distance_direct` without the periodic
    box: ``F_i = c s_i sum_j s_j r_ij / (r^2 + eps^2)^(3/2)``, energy = half of
    ``c s_i sum_j s_j / sqrt(r^2 + eps^2)``, virial = half of ``sum_j r_ij . F_ij``; pairs closer
    than the tree's opening criterion are summed exactly, farther ones through order-4
    multipole expansions. Results do not depend on the number of threads (bitwise).

    Parameters
    ----------
    position : ndarray, shape (N, 2)
        Centres in m.
    source : ndarray, shape (N,)
        Source strengths: charges in C (Coulomb) or masses in kg (gravity).
    coupling : float
        ``k`` in N m^2 / C^2 (Coulomb) or ``-G`` in N m^2 / kg^2 (gravity).
    softening2 : float
        Squared softening length in m^2.
    force : ndarray, shape (N, 2)
        Output: total force on each particle, N.
    energy : ndarray, shape (N,)
        Output: half the pair energy of each particle with all others, J (sum = potential).
    virial : ndarray, shape (N,)
        Output: half of ``sum_j r_ij . F_ij`` for each particle, J (sum = the pair virial).
    buffers : dict of str to ndarray
        From `tree_buffers`, kept by the caller between calls; replaced in place if N changed
        or the node arrays must grow.
    theta : float
        Opening angle; `THETA` by default.
    leaf_size : int
        Largest particle count of a leaf; `LEAF_SIZE` by default.
    """
    n = position.shape[0]
    if n == 0:
        return
    if buffers["order"].shape[0] != n:
        buffers.update(tree_buffers(n, leaf_size))
    b = buffers
    while True:
        nodes, n_leaves = build_tree(
            position, source, leaf_size, b["code"], b["key"], b["key_spare"], b["order"],
            b["order_spare"], b["sorted_x"], b["sorted_y"], b["sorted_q"], b["node_index"],
            b["node_geometry"], b["node_raw"], b["node_coef"], b["leaves"], b["depth_start"],
        )  # fmt: skip
        if nodes >= 0:
            break
        capacity = b["leaves"].shape[0]
        if capacity >= 2 * n - 1:
            raise RuntimeError("quadtree with more than 2 N - 1 nodes")  # cannot happen
        b.update(_node_arrays(min(2 * capacity, 2 * n - 1)))
    evaluate_tree(
        coupling, softening2, theta, b["order"], b["sorted_x"], b["sorted_y"], b["sorted_q"],
        b["node_index"], b["node_geometry"], b["node_coef"], b["leaves"], n_leaves,
        force, energy, virial,
    )  # fmt: skip
