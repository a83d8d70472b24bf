"""Neighbourhood search over exemplar windows, shared by the non-parametric samplers.

Pieces, each usable alone:

- :func:`square_offsets`, :func:`disk_offsets`: neighbourhood shapes as (row, col) offsets;
- :func:`toroidal_gather`: the neighbours of output pixels on a torus (periodic output);
- :func:`neighbour_table`: every exemplar pixel's neighbours at a given step and their squared
  norms as one row, a fixed value for those outside the exemplar (or wrapped, for an exemplar
  declared tileable);
- :class:`WindowRows`: the same rows (values and squared norm interleaved per neighbour)
  gathered on demand from the exemplar, for exemplars whose table would not fit;
- :class:`PatchMatrix`: every exemplar window as one row, so the weighted SSD of a batch of
  partially known output neighbourhoods against *all* exemplar windows is one matrix product
  (exact, not approximate): ``sum_k g_k ||E_k - N_k||^2 = sum_k g_k ||E_k||^2
  - 2 sum_k g_k E_k . N_k + sum_k g_k ||N_k||^2``;
- :func:`sample_near_best`: Efros & Leung's rule, a uniform draw among the windows within
  ``(1 + epsilon)`` of the best;
- :func:`sparse_subset`: a subset of pixels no two of which are closer than a spacing on the
  torus, preferring high priority, so a batch of them can be updated at once exactly as if one
  after the other.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "square_offsets",
    "disk_offsets",
    "gaussian_weights",
    "toroidal_gather",
    "neighbour_table",
    "PatchMatrix",
    "sample_near_best",
    "sparse_subset",
    "best_candidate",
    "Scratch",
    "Rows",
    "WindowRows",
]

#: Bytes of the indices :func:`neighbour_table` gathers a band of rows by (about a core's L2 cache).
_TABLE_BAND = 1 << 20


class Rows:
    """A 2-D array whose rows are gathered as single items (a void view): ``rows[idx]`` is
    ``array[idx]`` (shape ``idx.shape + (width,)``), two to five times faster than fancy
    indexing for the short rows of neighbourhood tables."""

    def __init__(self, array: np.ndarray):
        self.array = np.ascontiguousarray(array)
        n, width = self.array.shape
        self.width = width
        self._items = self.array.view(np.dtype((np.void, width * self.array.itemsize))).ravel()

    def __getitem__(self, idx) -> np.ndarray:
        got = self._items[idx]
        return got.view(self.array.dtype).reshape(np.shape(idx) + (self.width,))

    def take(self, idx: np.ndarray, out: np.ndarray) -> np.ndarray:
        """``self[idx]`` for 1-D ``idx``, written into the first ``len(idx)`` rows of ``out``
        (C-contiguous, ``width`` wide, the array's dtype), which are returned; in range, unchecked
        (``mode="clip"``: numpy's default mode writes to a new buffer, then copies it to out)."""
        got = out[:len(idx)]
        np.take(self._items, idx, out=got.view(self._items.dtype).reshape(-1), mode="clip")
        return got

    def __len__(self) -> int:
        return len(self.array)


def square_offsets(size: int) -> np.ndarray:
    """(size * size, 2) int32 (row, col) offsets of a centred square window, row-major."""
    if size < 1 or size % 2 == 0:
        raise ValueError(f"window size must be a positive odd number, got {size}")
    r = size // 2
    u, v = np.mgrid[-r:r + 1, -r:r + 1]
    return np.stack([u.ravel(), v.ravel()], axis=1).astype(np.int32)


def disk_offsets(radius: float) -> np.ndarray:
    """(K, 2) int32 offsets with 0 < u^2 + v^2 <= radius^2 (the centre excluded), nearest first."""
    r = int(np.floor(radius))
    u, v = np.mgrid[-r:r + 1, -r:r + 1]
    d2 = (u * u + v * v).ravel()
    keep = (d2 > 0) & (d2 <= radius * radius)
    order = np.argsort(d2[keep], kind="stable")
    return np.stack([u.ravel()[keep][order], v.ravel()[keep][order]], axis=1).astype(np.int32)


def gaussian_weights(offsets: np.ndarray, sigma: float) -> np.ndarray:
    """exp(-|offset|^2 / (2 sigma^2)) per offset, float32."""
    d2 = (offsets.astype(np.float64) ** 2).sum(axis=1)
    return np.exp(-d2 / (2.0 * sigma * sigma)).astype(np.float32)


def toroidal_gather(image: np.ndarray, rows, cols, offsets: np.ndarray, step: int = 1):
    """``image[(rows + step u) mod H, (cols + step v) mod W]`` for every offset: (B, K, ...)."""
    h, w = image.shape[:2]
    r = (np.asarray(rows)[:, None] + step * offsets[None, :, 0]) % h
    c = (np.asarray(cols)[:, None] + step * offsets[None, :, 1]) % w
    return image[r, c]


def neighbour_table(exemplar: np.ndarray, offsets: np.ndarray, step: int, wrap: bool,
                    outside: float, out: np.ndarray | None = None, tick=None,
                    cost: np.ndarray | None = None) -> np.ndarray:
    """Every exemplar pixel's row ``[X, Q]`` (float32, (H W + 1, K (C + 1)), the last row zero):
    X its neighbours ``exemplar[p + step u, q + step v]`` (K C values), Q their squared norms
    (K values); a neighbour outside the exemplar has X = 0 and Q = ``outside``. With ``wrap``
    every neighbour wraps. Filled a band of rows at a time, each band's K neighbours gathered
    as whole C-value items (``Rows``' void view) from the padded exemplar into the band's rows
    at once (K strided copies of C floats a pixel had cost 3-4x: a 1024^2 table of 5 channels
    0.9-1.3 s, now 0.25-0.36 s); ``out``, when given, is that array (reused across levels,
    which spares the fresh pages of a new one); ``tick()``, when given, after each band;
    ``cost`` (H, W), when given, is added to each pixel's Q values (a distance then gains
    ``cost`` times its weights' sum), band by band while it is in cache."""
    h, w, c = exemplar.shape
    k = len(offsets)
    du, dv = (np.asarray(offsets) * step).T
    m = int(np.abs(du).max(initial=0)), int(np.abs(dv).max(initial=0))
    pad = ((m[0], m[0]), (m[1], m[1]))
    squares = (exemplar * exemplar).sum(axis=2)
    if wrap:
        x_pad = np.pad(exemplar, (*pad, (0, 0)), mode="wrap")
        q_pad = np.pad(squares, pad, mode="wrap")
    else:
        x_pad = np.pad(exemplar, (*pad, (0, 0)))
        q_pad = np.pad(squares, pad, constant_values=outside)
    item = np.dtype((np.void, 4 * c))
    x_items = np.ascontiguousarray(x_pad, np.float32).reshape(-1, c).view(item).ravel()
    q_items = q_pad.astype(np.float32, copy=False).ravel()
    pw = w + 2 * m[1]
    shift = ((m[0] + du) * pw + m[1] + dv).astype(np.intp)  # each neighbour's flat offset
    table = np.empty((h * w + 1, k * (c + 1)), np.float32) if out is None else out
    table[-1] = 0
    band = max(1, _TABLE_BAND // (w * k * 8))  # a band's indices: about _TABLE_BAND bytes
    cols = np.arange(w, dtype=np.intp)
    for r0 in range(0, h, band):
        r1 = min(h, r0 + band)
        idx = (np.arange(r0, r1, dtype=np.intp)[:, None] * pw + cols).reshape(-1, 1) + shift
        rows = table[r0 * w:r1 * w]
        np.take(x_items, idx, out=rows[:, :k * c].view(item), mode="clip")
        np.take(q_items, idx, out=rows[:, k * c:], mode="clip")
        if cost is not None:
            rows[:, k * c:] += cost[r0:r1].reshape(-1, 1)
        if tick is not None:
            tick()
    return table


class WindowRows:
    """:func:`neighbour_table`'s rows computed when asked for, not stored: ``rows[idx]`` is
    (len(idx), K (C + 1)), per neighbour its C values then their squared norm (interleaved,
    where the table has all values first), for flat exemplar positions ``idx``. The exemplar is
    kept once as [X, Q] per pixel with a margin of ``margin`` pixels (zero and ``outside``, or
    wrapped), so a row is K gathers of C + 1 floats; :meth:`at` serves any step whose
    neighbourhood fits in the margin. 16 bytes a pixel for RGB, against the table's 4 K (C + 1).

    References
    ----------
    Neubeck, Zalesny & Van Gool 2004, 3.1, eq. 3 (the distance these rows enter).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> image = rng.random((9, 11, 3), dtype=np.float32)
    >>> offsets = disk_offsets(2)
    >>> table = neighbour_table(image, offsets, 2, False, 5.0)
    >>> rows = WindowRows(image, 4, False, 5.0).at(offsets, 2)[np.array([0, 40, 98])]
    >>> values = rows.reshape(3, len(offsets), 4)[:, :, :3].reshape(3, -1)
    >>> bool(np.allclose(values, table[[0, 40, 98], :3 * len(offsets)]))
    True
    """

    def __init__(self, exemplar: np.ndarray, margin: int, wrap: bool, outside: float):
        h, w, c = exemplar.shape
        m = margin
        xq = np.empty((h + 2 * m, w + 2 * m, c + 1), np.float32)
        if wrap:
            rows = (np.arange(-m, h + m) % h)[:, None]
            cols = np.arange(-m, w + m) % w
            xq[:, :, :c] = exemplar[rows, cols]
        else:
            xq[:, :, :c] = 0
            xq[m:m + h, m:m + w, :c] = exemplar
        np.einsum("ijc,ijc->ij", xq[:, :, :c], xq[:, :, :c], out=xq[:, :, c])
        if not wrap:
            xq[:m, :, c] = xq[h + m:, :, c] = xq[:, :m, c] = xq[:, w + m:, c] = outside
        self.shape, self.margin, self.channels = (h, w), m, c
        self.pixels = Rows(xq.reshape(-1, c + 1))

    def at(self, offsets: np.ndarray, step: int) -> _WindowRowsAt:
        """The rows for these offsets at this step (``step * |offset|`` within the margin)."""
        return _WindowRowsAt(self, offsets, step)


class _WindowRowsAt:
    def __init__(self, parent: WindowRows, offsets: np.ndarray, step: int):
        h, w = parent.shape
        m = parent.margin
        if step * int(np.abs(offsets).max(initial=0)) > m:
            raise ValueError(f"step {step} reaches past the margin of {m} pixels")
        self.parent, self.stride = parent, w + 2 * m
        self.koff = (step * (offsets[:, 0].astype(np.int64) * self.stride + offsets[:, 1]))
        self.width = len(offsets) * (parent.channels + 1)

    def __getitem__(self, idx) -> np.ndarray:
        w, m = self.parent.shape[1], self.parent.margin
        pr, pc = np.divmod(np.asarray(idx, np.int64), w)
        centre = (pr + m) * self.stride + (pc + m)
        got = self.parent.pixels[centre[..., None] + self.koff]
        return got.reshape(np.shape(idx) + (self.width,))


class PatchMatrix:
    """All exemplar windows of a shape, for exact weighted SSD against batches of neighbourhoods.

    ``positions`` (N, 2) are the window centres: every centre whose window lies inside the
    exemplar, or every pixel when ``wrap`` (an exemplar that tiles). Values are centred on the
    exemplar mean (distances are unchanged; float32 cancellation is smaller). A window's row holds,
    per offset (nearest the centre first), its squared norm then its C values, so the offsets
    within ``bound_radius`` of the centre are a prefix of the row: the SSD over them alone is a
    cheap lower bound of the full SSD (every term is non-negative), used by :meth:`sample`.
    ``batch_bytes``: the float32 bounds of the largest batch :meth:`sample` is given (B x N x 4);
    they and their test go to buffers of that size made once, whose pages are touched once as
    batches grow into them (fresh arrays a batch cost page faults that grew faster than the
    batch: 0.17 to 0.47 ms a pixel of Efros-Leung at 64^2 -> 128^2, large arrays always fresh).
    """

    #: Candidate rows re-ranked exactly at once (bounds the memory of :meth:`sample`).
    CHUNK = 1024

    def __init__(self, exemplar: np.ndarray, offsets: np.ndarray, wrap: bool = False,
                 bound_radius: int = 3, batch_bytes: int = 0):
        h, w, c = exemplar.shape
        order = np.argsort(np.abs(offsets).max(axis=1), kind="stable")
        self.order = order
        offsets = offsets[order]
        self.offsets = offsets
        self.mean = exemplar.reshape(-1, c).mean(axis=0).astype(np.float32)
        centred = (exemplar - self.mean).astype(np.float32)
        lo = (-offsets.min(axis=0)).clip(0)
        hi = offsets.max(axis=0).clip(0)
        if wrap:
            rows, cols = np.arange(h), np.arange(w)
        else:
            rows, cols = np.arange(lo[0], h - hi[0]), np.arange(lo[1], w - hi[1])
        if len(rows) == 0 or len(cols) == 0:
            raise ValueError(f"the exemplar ({w} x {h}) is smaller than the neighbourhood "
                             f"({hi[1] + lo[1] + 1} x {hi[0] + lo[0] + 1}); use a smaller window "
                             "or a larger exemplar")
        pr, pc = np.meshgrid(rows, cols, indexing="ij")
        self.positions = np.stack([pr.ravel(), pc.ravel()], axis=1).astype(np.int32)
        k = len(offsets)
        n = len(self.positions)
        values = np.empty((n, k, c + 1), np.float32)
        for j, (u, v) in enumerate(offsets):
            e = centred[(pr + u) % h, (pc + v) % w].reshape(n, c)
            values[:, j, 1:] = e
            values[:, j, 0] = (e * e).sum(axis=1)
        #: (N, K (C + 1)): per window and offset, the squared norm then the C values.
        self.matrix = values.reshape(n, k * (c + 1))
        self.rows = Rows(self.matrix)
        self.channels = c
        self.bound_columns = int((np.abs(offsets).max(axis=1) <= bound_radius).sum()) * (c + 1)
        self.batch_bytes = batch_bytes
        self._bounds = self._kept = None                  # sample's buffers, made on first use
        self._chunks = None

    def queries(self, neighbourhoods: np.ndarray, weights: np.ndarray):
        """Rows ``[g_k, -2 g_k N_k]`` per offset and the constants ``sum_k g_k |N_k|^2``, so that
        ``matrix @ query + const`` is the weighted SSD; also that constant over the inner
        offsets only, for the lower bound. Inputs in the caller's offset order."""
        b, k, c = neighbourhoods.shape
        q = (neighbourhoods[:, self.order] - self.mean).astype(np.float32)
        g = weights[:, self.order].astype(np.float32)
        query = np.empty((b, k, c + 1), np.float32)
        query[:, :, 0] = g
        np.multiply(q, -2.0 * g[:, :, None], out=query[:, :, 1:])
        terms = g * (q * q).sum(axis=2)
        inner = terms[:, :self.bound_columns // (c + 1)].sum(axis=1)
        return query.reshape(b, k * (c + 1)), terms.sum(axis=1), inner

    def distances(self, neighbourhoods: np.ndarray, weights: np.ndarray):
        """``sum_k weights[b, k] ||E_n,k - neighbourhoods[b, k]||^2`` for every window n: (B, N).

        ``neighbourhoods`` (B, K, C) in the exemplar's units; ``weights`` (B, K), zero for the
        neighbours that are not known. Also returns ``sum_k weights |neighbourhoods|^2`` per row,
        the size of the terms, for rounding tolerances.
        """
        query, const, _ = self.queries(neighbourhoods, weights)
        d = query @ self.matrix.T
        d += const[:, None]
        return d, const

    def sample(self, neighbourhoods, weights, epsilon: float, rng: np.random.Generator):
        """Efros & Leung's draw (see :func:`sample_near_best`) over all windows, exactly, with
        less arithmetic: the SSD over the inner offsets bounds each window's SSD from below;
        the full SSD of the best-bounded window bounds the minimum from above; only windows
        whose lower bound is within (1 + epsilon) of that upper bound are scored in full.
        Returns (window index, best distance) per row."""
        query, const, inner = self.queries(neighbourhoods, weights)
        b, n = len(query), len(self.matrix)
        tol = TOLERANCE * const
        nb = self.bound_columns
        if self._bounds is None or self._bounds.size < b * n:   # grown a quarter at a time,
            grown = 0 if self._bounds is None else self._bounds.size * 5 // 4   # to the cap
            self._bounds = np.empty(max(b * n, min(grown, self.batch_bytes // 4)), np.float32)
            self._kept = np.empty(self._bounds.size, bool)
        lower = self._bounds[:b * n].reshape(b, n)
        np.matmul(query[:, :nb], self.matrix[:, :nb].T, out=lower)
        lower += inner[:, None]
        guess = lower.argmin(axis=1)
        upper = np.einsum("ij,ij->i", self.rows[guess], query) + const
        keep = np.less_equal(lower, ((1.0 + epsilon) * upper.clip(0) + 2 * tol)[:, None],
                             out=self._kept[:b * n].reshape(b, n))
        flat = np.flatnonzero(keep)
        if len(flat) > b * n // 8:  # bounds too loose to pay: score everything
            d = lower
            np.matmul(query, self.matrix.T, out=d)
            d += const[:, None]
            return sample_near_best(d, epsilon, rng, tol)
        rows, cols = np.divmod(flat, n)
        d = np.empty(len(flat), np.float32)
        queries = Rows(query)
        if self._chunks is None:                      # the rows a chunk re-ranks, gathered
            self._chunks = np.empty((2, self.CHUNK, self.matrix.shape[1]), np.float32)
        for s in range(0, len(flat), self.CHUNK):
            sl = slice(s, s + self.CHUNK)
            d[sl] = np.einsum("ij,ij->i", self.rows.take(cols[sl], self._chunks[0]),
                              queries.take(rows[sl], self._chunks[1]))
        d += const[rows]
        starts = np.flatnonzero(np.r_[True, rows[1:] != rows[:-1]])
        best = np.minimum.reduceat(d, starts).clip(0)
        ok = np.flatnonzero(d <= ((1.0 + epsilon) * best + tol)[rows])
        return cols[ok[_uniform_pick(rows[ok], b, rng)]], best


#: Rounding tolerance of the float32 distances, relative to the size of their terms.
TOLERANCE = 1e-5


def _uniform_pick(rows: np.ndarray, n_rows: int, rng: np.random.Generator) -> np.ndarray:
    """For sorted row labels (each of 0..n_rows-1 present), one index per row, uniformly."""
    counts = np.bincount(rows, minlength=n_rows)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    return starts + (rng.random(n_rows) * counts).astype(np.int64).clip(max=counts - 1)


def sample_near_best(d: np.ndarray, epsilon: float, rng: np.random.Generator,
                     tolerance: np.ndarray | float = 0.0):
    """Per row of ``d`` (B, N), a column drawn uniformly among those with
    ``d <= (1 + epsilon) * min(d) + tolerance`` (Efros & Leung 1999). Returns (index, min)."""
    best = d.min(axis=1).clip(0)
    ok = d <= ((1.0 + epsilon) * best + tolerance)[:, None]
    rows, cols = np.divmod(np.flatnonzero(ok), d.shape[1])
    return cols[_uniform_pick(rows, len(d), rng)], best


class Scratch:
    """Buffers reused from call to call (grown, never shrunk): a visit's gathered rows fill the
    same pages every time, where fresh arrays of a few MB each cost their page faults on every
    call (with glibc's mmap threshold pinned at 1 MiB, as the benchmarks do: best_candidate's
    fresh gathers had taken a third of multiscale_mrf's time at 256 -> 512)."""

    def __init__(self):
        self._arrays = {}

    def get(self, name: str, rows: int, width: int, dtype=np.float32) -> np.ndarray:
        """A C-contiguous (rows, width) array of ``dtype``, its contents undefined."""
        have = self._arrays.get(name)
        if have is None or have.shape[0] < rows or have.shape[1:] != (width,) \
                or have.dtype != dtype:
            grown = 0 if have is None or have.shape[1:] != (width,) else have.shape[0] * 5 // 4
            have = self._arrays[name] = np.empty((max(rows, grown), width), dtype)
        return have[:rows]


def _gather(table, idx, scratch: Scratch | None, name: str) -> np.ndarray:
    """``table[idx]`` (1-D ``idx``), into ``scratch``'s buffer ``name`` when ``table`` is a
    :class:`Rows` and there is one."""
    if scratch is None or not isinstance(table, Rows):
        return table[idx]
    return table.take(idx, scratch.get(name, len(idx), table.width, table.array.dtype))


def best_candidate(table, cand: np.ndarray, z: np.ndarray, current: np.ndarray,
                   none: int, scratch: Scratch | None = None) -> np.ndarray:
    """Per output pixel, the candidate exemplar position with the least distance ``table[p] . z``
    where it beats ``current`` (else ``current``): the candidate step of the MRF samplers.

    ``table`` is a :class:`Rows` of a :func:`neighbour_table` or a :class:`WindowRows` (``z`` in
    its layout); ``cand`` (B, M) holds candidate rows with ``none`` for "no candidate".
    Duplicates and the current position are scored once: only the distinct (pixel, candidate)
    pairs are gathered (a refining level offers about 1.2 a pixel in 9 columns; a level of
    the MRF at 256 -> 512 about 3.2 in 30). ``scratch``, when given, holds the gathered rows
    from call to call (:class:`Scratch`).

    References
    ----------
    Neubeck, Zalesny & Van Gool 2004, 3.1, eq. 3 (the distance); Ashikhmin 2001, fig. 8 (the
    candidates).

    Examples
    --------
    >>> table = Rows(np.array([[1.0, 0.0], [0.0, 1.0], [0.5, 0.5]], np.float32))
    >>> z = np.array([[1.0, 0.0], [0.0, 1.0]], np.float32)
    >>> cand = np.array([[1, 2, 3], [0, 0, 3]])
    >>> best_candidate(table, cand, z, np.array([0, 1]), 3).tolist()
    [1, 0]
    """
    b = len(cand)
    cand.sort(axis=1)
    kept = np.empty(cand.shape, bool)  # a candidate's first copy, not the current, not none
    kept[:, 0] = True
    np.not_equal(cand[:, 1:], cand[:, :-1], out=kept[:, 1:])
    kept &= cand != current[:, None]
    kept &= cand < none
    pixel = np.nonzero(kept)[0]
    rows = Rows(z)
    d = np.einsum("pk,pk->p", _gather(table, cand[kept], scratch, "candidates"),
                  _gather(rows, pixel, scratch, "queries"))
    now = np.einsum("pk,pk->p", _gather(table, current, scratch, "candidates"), z)
    scored = np.full(cand.shape, np.inf, np.float32)
    scored[kept] = d
    pick = scored.argmin(axis=1)
    every = np.arange(b)
    return np.where(scored[every, pick] < now, cand[every, pick], current)


#: The 8 neighbouring cells' offsets (row, col), as columns to broadcast against the cells.
_AROUND = np.array([(dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dy or dx])


def sparse_subset(rows, cols, priority, shape, spacing: int, rng: np.random.Generator):
    """Mask over the given pixels keeping a subset whose members are pairwise at toroidal
    Chebyshev distance >= ``spacing``, the best ``priority`` first within each neighbourhood.

    The torus is cut into cells at least ``spacing`` wide (randomly shifted each call); each cell
    keeps its highest-priority pixel, and of two kept pixels in neighbouring cells that are too
    close the lower-priority one is dropped. Not maximal, but every kept pixel is a local maximum.
    """
    h, w = shape
    rows = np.asarray(rows)
    cols = np.asarray(cols)
    gy, gx = max(1, h // spacing), max(1, w // spacing)
    oy, ox = rng.integers(h), rng.integers(w)
    cy = ((rows - oy) % h) * gy // h
    cx = ((cols - ox) % w) * gx // w
    cell = cy * gx + cx
    order = np.lexsort((-priority, cell))
    first = np.ones(len(order), bool)
    first[1:] = cell[order][1:] != cell[order][:-1]
    chosen = order[first]
    # The kept pixels' cells, ascending (the sort's first key): a neighbouring cell's pixel is
    # looked up by bisection, so the work is the pixels', never the grid's (gy gx cells).
    me = cell[chosen]
    my_r, my_c, my_p = rows[chosen], cols[chosen], priority[chosen]
    ccy, ccx = me // gx, me % gx
    # the 8 neighbouring cells of each kept pixel's cell at once: (8, kept)
    other = ((ccy + _AROUND[:, :1]) % gy) * gx + (ccx + _AROUND[:, 1:]) % gx
    at = np.minimum(np.searchsorted(me, other), len(me) - 1)
    valid = (other != me) & (me[at] == other)
    ddy = np.abs(my_r[at] - my_r) % h
    ddx = np.abs(my_c[at] - my_c) % w
    close = (np.minimum(ddy, h - ddy) < spacing) & (np.minimum(ddx, w - ddx) < spacing)
    op = my_p[at]
    beaten = (op > my_p) | ((op == my_p) & (other < me))
    keep_chosen = ~(valid & close & beaten).any(axis=0)
    mask = np.zeros(len(rows), bool)
    mask[chosen[keep_chosen]] = True
    return mask
