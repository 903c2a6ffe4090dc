"""Neighbour pairs and sums over neighbours.

Every SPH sum in refsph runs over *half pairs* (i < j): each interacting pair appears once, the pair
quantity is computed once, and it is added to i and (with the sign or weight the equation asks for) to j.
That halves the arithmetic and makes pairwise-antisymmetric forces conserve momentum to round-off.

* :func:`find_pairs` -- half pairs within a radius from ``scipy.spatial.cKDTree.query_pairs``.
* :class:`VerletList` -- a pair list built with a skin (radius 2h + skin) and reused until some
  particle has moved more than skin/2 since the build: then no pair can have entered the 2h support
  unseen (Verlet 1967; Allen & Tildesley, "Computer Simulation of Liquids", Sec. 5.3).
  Pairs farther than 2h simply get W = 0 and grad W = 0.
* :func:`scatter_add` -- sums over pairs onto particles as ``np.bincount``.
* :class:`PairSum` -- the sums that SPH needs most, "add w_j t_ij to i and +-w_i t_ij to j", as two sparse
  matrix-vector products whose stored values are the pair values t themselves (no gathers, no bincount).
* :class:`PairBlocks` -- a pair list cut into blocks of consecutive pairs, each with its own PairSum, so that a
  rate evaluation works on arrays that fit in the CPU cache (and can run blocks on several threads).

Why blocks. A pair array at the paper's cutting resolution has 0.5-0.8 million numbers (4-7 MB). Every NumPy
operation on it streams it from main memory, and every temporary of that size is a fresh allocation whose
pages the kernel must fault in and zero. Cut into blocks of ``PAIR_BLOCK`` pairs (1 MB per array; the dozen or
so arrays of one block's evaluation stay in the CPU's caches) the same operations reuse cached, already
mapped memory: ESPH's rate evaluation at the paper's cutting resolution is 1.5x faster on one core
(``benchmarks/pair_blocks.py``). The block
layout depends only on the pair list, never on the number of threads, and per-block results are added in
block order, so a run gives the same bits on any number of threads (``tests/test_neighbours.py``,
``tests/test_driver.py``).
"""
from __future__ import annotations

import os

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

__all__ = ["find_pairs", "VerletList", "scatter_add", "pair_count_per_particle", "PairSum", "PairBlocks",
           "PAIR_BLOCK", "available_cores", "threads_per_job", "check_threads", "check_half_pairs"]

PAIR_BLOCK = 2**17        # pairs per block of a PairBlocks: 1 MB per float array (benchmarks/pair_blocks.py)


def find_pairs(x: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Half pairs (I, J), I < J, with |x_I - x_J| <= radius, sorted by I then J."""
    x = np.asarray(x, dtype=float)
    if x.ndim != 2:
        raise ValueError(f"positions must have shape (N, d), got {x.shape}")
    if not radius > 0:
        raise ValueError(f"neighbour radius must be positive, got {radius!r}")
    pairs = cKDTree(x).query_pairs(radius, output_type="ndarray")     # rows (i, j) with i < j, unordered
    if len(pairs) == 0:
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
    key = pairs[:, 0].astype(np.int64) * len(x) + pairs[:, 1]          # sort by I then J: one integer key
    key.sort()
    I, J = np.divmod(key, len(x))
    return I.astype(np.intp, copy=False), J.astype(np.intp, copy=False)


def check_half_pairs(I: np.ndarray, J: np.ndarray, n: int) -> None:
    """Refuse a pair list that is not refsph's convention: *half pairs*, each interacting pair once with I < J
    (so no self-pair i = i and not both (i, j) and (j, i)), no pair twice, indices in [0, n). A full
    (both-direction) list, the usual GPU layout, would double every sum; this says so instead."""
    I, J = np.asarray(I), np.asarray(J)
    if I.shape != J.shape or I.ndim != 1:
        raise ValueError(f"pair lists I and J must be 1-D arrays of one length, got shapes {I.shape}, {J.shape}")
    if not len(I):
        return
    if min(I.min(), J.min()) < 0 or max(I.max(), J.max()) >= n:
        raise ValueError(f"pair indices must lie in [0, {n})")
    if np.any(I == J):
        k = int(np.flatnonzero(I == J)[0])
        raise ValueError(f"pair {k} is a self-pair ({I[k]}, {J[k]}); refsph expects half pairs: each interacting "
                         "pair once with I < J and no self-pairs")
    if np.any(I > J):
        k = int(np.flatnonzero(I > J)[0])
        raise ValueError(f"pair {k} is ({I[k]}, {J[k]}) with I > J: refsph expects half pairs (each interacting "
                         "pair once, I < J); a full (both-direction) neighbour list would count every pair twice")
    key = I.astype(np.int64) * n + J
    if len(key) > 1 and not np.all(key[1:] > key[:-1]) and len(np.unique(key)) != len(key):
        raise ValueError("a pair appears twice: refsph expects half pairs, each interacting pair once (I < J)")


def scatter_add(index: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """out[k] = sum of values[p] over p with index[p] == k; values of shape (M,) or (M, c)."""
    if values.ndim == 1:
        return np.bincount(index, values, minlength=n)
    out = np.empty((n,) + values.shape[1:])
    flat = values.reshape(len(values), int(np.prod(values.shape[1:])))
    outf = out.reshape(n, -1)
    for c in range(flat.shape[1]):
        outf[:, c] = np.bincount(index, flat[:, c], minlength=n)
    return out


class PairSum:
    """Sums over half pairs (I, J) as sparse products with per-pair values.

    Half pairs sorted by I (as :func:`find_pairs` returns them) are the non-zero pattern of an N x N matrix
    U in CSR storage order, so an array t of one value per pair can serve directly as the stored values of
    U. Then, for a per-particle array w,

        symmetric(t, w)_i     = sum_j w_j t_ij,  t_ji = +t_ij   =  (U w + U^T w)_i
        antisymmetric(t, w)_i = sum_j w_j t_ij,  t_ji = -t_ij   =  (U w - U^T w)_i

    i.e. each pair adds w_j t to i and (+ or -) w_i t to j. Two single-vector sparse products cost about
    1 ns per pair, against about 5 ns for two weighted ``np.bincount`` calls plus the gathers w[J], w[I].
    The pattern is built once per pair list; only the values change between evaluations. Pairs not sorted
    by I are accepted (their values are then permuted into storage order at every call).
    """

    def __init__(self, I: np.ndarray, J: np.ndarray, n: int):
        I, J = np.asarray(I), np.asarray(J)
        self.n, self.n_pairs = int(n), len(I)
        self._order = None
        if len(I) > 1 and np.any(I[1:] < I[:-1]):
            self._order = np.argsort(I, kind="stable")
            I, J = I[self._order], J[self._order]
        index = np.int32 if max(n, len(I)) < 2**31 - 1 else np.int64
        indptr = np.zeros(n + 1, dtype=index)
        np.cumsum(np.bincount(I, minlength=n), out=indptr[1:])
        self._U = sp.csr_matrix((np.zeros(len(I)), np.asarray(J, dtype=index), indptr), shape=(n, n))
        self._UT = self._U.T                                # CSC view of the same arrays

    def _values(self, t: np.ndarray) -> None:
        t = np.asarray(t, dtype=float)
        if t.shape != (self.n_pairs,):
            raise ValueError(f"expected one value per pair ({self.n_pairs}), got shape {t.shape}")
        t = np.take(t, self._order) if self._order is not None else np.ascontiguousarray(t)
        self._U.data = self._UT.data = t

    def symmetric(self, t: np.ndarray, w: np.ndarray) -> np.ndarray:
        """sum over pairs: w_j t_p into i, w_i t_p into j."""
        self._values(t)
        return self._U @ w + self._UT @ w

    def antisymmetric(self, t: np.ndarray, w: np.ndarray) -> np.ndarray:
        """sum over pairs: w_j t_p into i, -w_i t_p into j."""
        self._values(t)
        return self._U @ w - self._UT @ w


class PairBlocks:
    """Half pairs (I, J) cut into consecutive blocks of at most ``size`` pairs (None: ``PAIR_BLOCK``).

    A block covers the particles ``window = slice(lo, hi)`` that its pairs touch (lo = its smallest index,
    hi - 1 its largest); its :class:`PairSum` ``sums`` works on local indices I - lo, J - lo, i.e. on the
    per-particle arrays cut to ``window`` (``blk.local(w)``), and returns sums over that window only. With
    pairs sorted by I and particles numbered so that neighbours have nearby numbers (a lattice), a window is
    a little longer than the block's rows; a block whose particles pair with rows far down the array (mirror
    ghosts, tool particles: they come last) has a long window, which costs time but not accuracy.

    ``map(fn)`` calls ``fn(block)`` for every block -- a block has ``I``, ``J`` (global indices), ``sl`` (its
    slice of the whole pair list), ``window`` and ``sums`` -- and returns the results in block order.
    ``reduce(fn)`` adds results of shape (..., hi - lo) into one array of shape (..., n), block by block in
    block order, so the total does not depend on ``threads``. With ``threads`` > 1 the blocks run on a thread
    pool: NumPy's array operations and SciPy's sparse products release the GIL, so the blocks of one
    evaluation really do run at the same time. One PairBlocks serves one evaluation at a time (each block's
    PairSum holds the pair values of the sum in progress).
    """

    _pool = None                                            # the thread pool, made on first use

    class Block:
        def __init__(self, I, J, sl):
            self.I, self.J, self.sl = I, J, sl
            lo = int(min(I.min(), J.min())) if len(I) else 0
            hi = int(max(I.max(), J.max())) + 1 if len(I) else 0
            self.window = slice(lo, hi)
            self.sums = PairSum(I - lo, J - lo, hi - lo)

        def local(self, w: np.ndarray) -> np.ndarray:
            """The rows of per-particle array w inside this block's window (a view)."""
            return w[self.window]

    def __init__(self, I: np.ndarray, J: np.ndarray, n: int, size: int | None = None, threads: int = 1):
        size = PAIR_BLOCK if size is None else size
        if size < 1:
            raise ValueError(f"block size must be a positive number of pairs, got {size!r}")
        threads = check_threads(threads)
        I, J = np.asarray(I), np.asarray(J)
        check_half_pairs(I, J, n)
        self.n, self.n_pairs, self.size = int(n), len(I), int(size)
        self.blocks = [self.Block(I[a:a + self.size], J[a:a + self.size], slice(a, a + self.size))
                       for a in range(0, max(len(I), 1), self.size)]
        self.threads = int(threads)

    def map(self, fn, items=None) -> list:
        """[fn(item) for item in items] (default: the blocks), on the thread pool if ``threads`` > 1 and the pair
        list has more than one block (a list that fits in one block is too small to pay for the threads)."""
        items = self.blocks if items is None else list(items)
        if self.threads == 1 or len(self.blocks) == 1 or len(items) == 1:
            return [fn(b) for b in items]
        if self._pool is None:
            from concurrent.futures import ThreadPoolExecutor
            self._pool = ThreadPoolExecutor(self.threads)
        return list(self._pool.map(fn, items))

    def reduce(self, fn) -> np.ndarray:
        """sum over blocks of fn(block), an array of shape (..., window length), into shape (..., n)."""
        results = self.map(fn)
        total = np.zeros(results[0].shape[:-1] + (self.n,))
        for blk, r in zip(self.blocks, results):
            total[..., blk.window] += r
        return total

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None

    def __del__(self):
        self.close()


def available_cores() -> int:
    """CPU cores this process may run on (the affinity mask where the OS has one). A container's CPU quota is not
    seen here, nor other work on the machine: where several runs share the cores, give each its share
    (``Numerics.threads``, ``refsph run --set threads=N``, :func:`threads_per_job`)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:                                  # not on Linux
        return os.cpu_count() or 1


def check_threads(threads, allow_auto: bool = False) -> int:
    """The thread count as an int: a whole number >= 1, or 0 for one thread per available core where
    ``allow_auto`` (``Numerics.threads``); ValueError otherwise. The one check of a thread count in refsph."""
    low = 0 if allow_auto else 1
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < low:
        raise ValueError(f"threads must be a whole number >= {low}" + (" (0 = one thread per available core)"
                                                                       if allow_auto else "") + f", got {threads!r}")
    return available_cores() if threads == 0 else int(threads)


def threads_per_job(n_jobs: int) -> int:
    """Threads for each of ``n_jobs`` runs sharing this machine: its share of the available cores (at least 1)."""
    return max(1, available_cores() // max(1, int(n_jobs)))


def pair_count_per_particle(I: np.ndarray, J: np.ndarray, n: int) -> np.ndarray:
    """Number of neighbours of each particle (excluding itself)."""
    return np.bincount(I, minlength=n) + np.bincount(J, minlength=n)


class VerletList:
    """Half-pair list within ``cutoff + skin``, rebuilt only when needed.

    ``update(x)`` returns (I, J) and rebuilds if max |x - x_build| > skin / 2.
    ``n_builds`` counts the builds (a diagnostic for the benchmark and the summary).
    """

    def __init__(self, cutoff: float, skin: float):
        if not cutoff > 0:
            raise ValueError(f"cutoff must be positive, got {cutoff!r}")
        if not skin >= 0:
            raise ValueError(f"skin must be non-negative, got {skin!r}")
        self.cutoff = float(cutoff)
        self.skin = float(skin)
        self.n_builds = 0
        self.x_build: np.ndarray | None = None
        self.I = np.zeros(0, dtype=np.intp)
        self.J = np.zeros(0, dtype=np.intp)

    def build(self, x: np.ndarray, track: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Pairs of ``x`` within cutoff + skin. ``track``: the positions whose displacement decides the next
        rebuild, if not ``x`` itself (e.g. the real particles, when ``x`` also holds mirror ghosts that move
        with them)."""
        self.I, self.J = find_pairs(x, self.cutoff + self.skin)
        self.x_build = np.array(x if track is None else track, dtype=float, copy=True)
        self.n_builds += 1
        return self.I, self.J

    def needs_rebuild(self, x: np.ndarray) -> bool:
        if self.x_build is None or self.x_build.shape != x.shape:
            return True
        d = x - self.x_build
        return float(np.sqrt(np.max(np.einsum("ik,ik->i", d, d)))) > 0.5 * self.skin

    def update(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self.needs_rebuild(x):
            return self.build(x)
        return self.I, self.J
