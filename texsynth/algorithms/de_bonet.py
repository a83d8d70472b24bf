"""De Bonet's multiresolution sampling of a pyramid conditioned on its parent structure.

Forsyth & Ponce, section 11.3.3, Algorithm 11.5 and exercise 1 (after De Bonet, SIGGRAPH 1997).

    Make a pyramid pe of the exemplar and an empty pyramid pw of the output size.
    Copy pe's coarsest level into pw (tiled from a random offset when pw is larger).
    For each finer level l, coarse to fine, for each location x of pw's level l:
        its parent structure is the vector of pw's values at x's position in the coarser
        levels l+1 .. l+depth;
        collect every location of pe's level l whose parent structure is within ``threshold``;
        copy the value of one of them chosen uniformly at random.
    Synthesize the output image from pw.

Pyramids: what is copied and synthesized is a Laplacian pyramid (``texsynth.blocks.pyramid``'s
periodic ``LaplacianPyramid``), and each level's value at a location also carries the K oriented
responses of the steerable pyramid there, the filter responses De Bonet added to his Laplacian
levels: a parent structure is then orientation-aware (Laplacian values, oriented responses). One
choice copies all of a location's values for every colour channel (joint colour vectors:
measured against PCA channels sampled apart, as few invented colours or fewer and 2-4x faster).
Collapsing copied *steerable* coefficients instead (a tight frame, so synthesis projects them)
lost 30-60% of the band energy at thresholds 0.5-1 (blur); the Laplacian sum keeps it within
about 10%.

Matching (exercise 1; no blank search): a level's exemplar parent structures, projected on their
leading principal components, go into one ``scipy.spatial.cKDTree``; the output's locations are
answered in batches by radius-bounded k-nearest queries, uniform among all hits (see
:class:`BallSampler`). Projection is linear, so each ancestor level's values are projected once
and a location sums their bilinear readings (:class:`ParentSpace`): it gathers a few numbers per
ancestor instead of its whole parent structure.

Large photos (issue 25: a 12 MP photo to 2048^2): every pixel of the finest level may be
copied, so it is analysed whole, but nothing of the work is held at its size beyond its values
and one float32 table of projected parent structures (24 bytes a pixel): the table is upsampled
from the ancestors by strided slices, one per phase, in blocks of rows; the channels' full-size
transforms run side by side; each level's table and tree are freed before the next's are built.
12 MP to 2048^2 (medians of 3 runs each, old and new alternating, on a loaded machine): peak
growth of resident memory 1654 -> 950 MiB (the crop's: 227 -> 216), CPU time 1.48 -> 1.33 of
the crop's (8.6 -> 5.8 s beyond it), the output bit for bit the same.

Deviations, one line each:
- a coarser level is read at x's own position (bilinear, on the torus), not at the replicated
  pixel x // 2: the four children of a parent then differ, and ``threshold`` 0 copies the
  exemplar instead of shuffling every 2 x 2 block at every level;
- each ancestor level is divided by the exemplar's spread at that level, and the vector is
  compared on its first ``MAX_DIMS`` principal components (at depth 3, finest level: 77% of the
  variance on pebbles01, 66% on green_leaves; 12 components, 97% / 88%, took 4x the time and
  changed the output's band energies by under 10%);
- ``threshold`` is in units of the median distance from an exemplar parent structure to its
  nearest other one, so its meaning does not depend on the level or the texture;
- when no exemplar location is within ``threshold``, the nearest parent structure's is copied;
- the ball is searched approximately (kd-tree ``eps`` = ``EPS``): only true members are drawn,
  some may be missed (at 512 -> 1024 on gravel: 25% less CPU, patch and structure distances
  unchanged or lower); the nearest parent structure, where the ball is empty, is approximate too
  (``NEAREST_EPS``): a third of the finest level's locations at 2048 need it, and exact it took
  40% of the CPU;
- production sizes (k-coherence, after Ashikhmin 2001, section 3, and Tong et al. 2002): a level
  with more than ``COHERENT_PIXELS`` locations first draws uniformly among its coherent
  candidates within ``threshold`` (the exemplar children of its four bilinear parents' sources,
  at its offset from each: :func:`coherent_candidates`), and takes the nearest of them where
  none is within (Tong et al.'s best candidate; searching the ball there drew, along the
  coarsest level's quilt cuts, locations continuing neither side: a band of scrambled bricks
  some 60 pixels wide on a brick wall at 2048^2, issue 41; now a cut between two copies, a
  thinner band where the 512^2 level searched too); a level of fewer than
  ``COHERENT_PIXELS`` locations drawing among them searches the ball there (the nearest
  candidate on every level: repetition peak 0.22-0.36 and seam ratio 0.79-0.94 on a grain
  96 -> 192, seeds 0-3; with the search 0.13-0.17 and 0.95-0.98); the draw is then among part
  of the ball
  (on gravel at 1024 -> 2048 the ball holds one point or none for 99% of the finest level's
  locations; a candidate is inside for 67% of them, the ball is not empty for 68%); with the
  rest: patch distance 0.224 -> 0.215, structure 0.159 -> 0.152 on gravel, 0.414 -> 0.403 and
  0.211 -> 0.211 on a brick wall, in a quarter of the CPU time;
- the exemplar pyramid is built from its periodic component (Moisan), so the border jump of a
  non-tiling photo gives no false parents; output values are clipped to the exemplar's range;
- where the output's coarsest level is a crop of the exemplar's (smaller on both sides: a photo
  larger than the output), it is quilted as below, from blocks of a ``CROP_CELLS``-th of its
  side (at least ``CROP_BLOCK``), and every level then draws among coherent candidates (the
  ball first on levels of up to ``COHERENT_PIXELS`` locations had left the coherent candidates
  of 16-23% of every finer level's locations outside the threshold, 4-6% from a crop of the
  photo, each then a search:
  a 12 MP photo to 2048^2 took 2.7x its 1024^2 crop's CPU time, now 1.8x: 22.0 -> 14.3 s,
  medians of 3 alternating runs on a loaded machine; seeds 0-2: seam ratio 1.06, 1.10, 1.05 ->
  1.00, 1.04, 1.09, gradient ratio 1.08, 1.06, 1.07 -> 1.03, 1.02, 1.02, the stones whole);
- where the output's coarsest level is otherwise not a whole number of the exemplar's (as wide
  as it, not as tall, or the other way round), the copy's offset is drawn among those whose
  continuation past the copy's end is nearest to its start on every level (on G_S alone, the
  seam ratio from a 12 MP photo to 2048^2 was 1.07-1.14 on seeds 0-2; then 1.05-1.10, when
  such a photo's coarsest level was copied), and its copied G_S is replaced
  by its periodic component (Moisan): the crop's wrap would be a seam, and coherent sampling
  would carry it down (it still does in part: the finer levels copy the photo nearly as it is,
  so the wrap is a straight boundary between two copies, rougher than 3/4 of the lines);
- where the output's coarsest level is larger than the exemplar's (an output larger than the
  photo), it is not the exemplar's tiled but quilted from it on the torus (Efros & Freeman 2001,
  2.1: ``blocks.quilting.torus_quilt``; blocks of the exemplar's coarsest side, a quarter of it
  overlapping, no block at a neighbour's offset or within a third of that side of another's
  source), and every level then draws among coherent candidates: tiled, each finer level's
  parent structure found the exemplar's own location again (65% of the finest level copied
  the tiling's offset from a 256 crop to 512), so the output was the photo laid 2 x 2
  (repetition peak 0.83 on a rock face, 0.84 on bricks, the photos' 0.13, 0.33; now 0.11 and
  0.25 with seed 0; 1024 -> 2048 0.86 -> 0.18); the ball alone scrambled the levels below the
  cuts (structure distance 0.26 on the 34 textures 128 -> 256, tiled 0.18, now 0.16);
- an output with a side under 8 pixels has no pyramid level to synthesize: it is the periodic
  component of an exemplar crop (which tiles; the crop's own wrap would be a seam).

References
----------
De Bonet 1997; Forsyth & Ponce, section 11.3.3, Algorithm 11.5 and exercise 1;
Ashikhmin 2001, section 3; Tong et al. 2002; Moisan 2011.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from ..blocks.parallel import run
from ..blocks.periodic import periodic_component, periodic_spectrum
from ..blocks.pyramid import LaplacianPyramid, SteerablePyramid, pyramid_depth
from ..blocks.quilting import block_count, torus_quilt
from ..registry import Method, Param, register

__all__ = [
    "de_bonet",
    "pyramid_features",
    "channel_levels",
    "parent_structure",
    "ParentSpace",
    "coherent_candidates",
    "sample_pyramid",
    "BallSampler",
    "tiled_subset",
    "quilted",
]

#: Output locations matched at once (bounds the query block).
CHUNK = 1 << 14
#: A level with more output locations than this first draws among coherent candidates.
COHERENT_PIXELS = 512 * 512
#: Principal components of the parent structure the search compares.
MAX_DIMS = 6
#: Approximation of the kd-tree search (scipy's ``eps``): a ball member may be missed
#: where a nearer-than-``(1 + EPS)``-times candidate was found first.
EPS = 1.0
#: Approximation of the nearest-point search where the ball is empty: a point at most
#: ``1 + NEAREST_EPS`` times as far as the nearest may be copied.
NEAREST_EPS = 3.0
#: Exemplar locations a level's kd-tree holds at most (a 1024^2 exemplar's finest level); a
#: larger level is indexed on tiles of ``TILE`` x ``TILE`` of its locations, evenly spread.
TREE_POINTS = 1 << 20
TILE = 64
#: Where the output's coarsest level is quilted: a block's side, its overlap and the radius
#: of the offsets it keeps away from, over the exemplar's coarsest side (De Bonet 1997 notes);
#: where the output's is a crop of it (smaller on both sides), over a ``CROP_CELLS``-th of the
#: output's side (12 MP photo to 2048^2, seed 0: 2, 3 and 4 cells, seam
#: ratio 1.07, 1.02 and 1.00, gradient ratio 1.01, 1.02, 1.03; one cell, seam 0.85).
#: The overlap is Efros & Freeman's quarter of a block from the exemplar's side (issue 41: an
#: eighth left the last row and column, cut against the first as well, too narrow a strip to
#: meet both: the seam ratio in phase of a brick wall 1024 -> 2048 was 0.82-1.20 on seeds
#: 0-7, now 0.95-1.01), an eighth of a crop's cell (a quarter there: seam ratio from a 12 MP
#: photo to 2048^2 0.97, 0.91, 0.85 on seeds 0-2, the wrap through a stone fused at a cut).
QUILT_BLOCK, QUILT_OVERLAP, QUILT_RADIUS = 1.0, 0.25, 1 / 3
CROP_OVERLAP = 0.125
#: A smaller crop is copied (and its wrap made periodic): its blocks would overlap by a
#: location, and a thin output's quilt did not tile (tests/test_refusals.py).
CROP_CELLS, CROP_BLOCK = 4, 8
#: Rows of an exemplar level projected at a time (on the cores, progress between).
EXEMPLAR_ROWS = 64
#: A query among coherent candidates in a free query's time (the cost model's figure), and
#: one on a level that searches no ball where none fits (at least ``COHERENT_PIXELS``
#: locations; issue 41: 1024^2 -> 2048^2 took 0.72-0.78 of the CPU time, a 12 MP photo 0.80;
#: predicted over measured time, one run each on a loaded machine, 1.08 -> 1.17 on a brick wall
#: 1024^2 -> 2048^2 and 0.92 -> 0.97 on the 12 MP photo, 1.6 and 1.2 at 0.56).
COHERENT_COST, NEAREST_COST = 0.56, 0.42
#: Seconds on the reference machine a quilted block takes (its search, cuts and masks: 2.4-2.6
#: ms CPU at load 14, 1.6 ms quiet, from 32^2 to 512^2 and 1024^2 and 64^2 to 1024^2; the
#: 1849 blocks of 32^2 -> 1024^2 took 57 % of its CPU time, and the model had no term).
QUILT_COST = 2.7e-3
#: Work, in free queries, per square root of a level's exemplar locations (its projection and
#: index: 7-9, 26, 60, 107, 194 and 190 ms CPU at 32^2 to 1024^2, about proportional to the
#: side, the first queries' chunk 0.3-0.7x that more; 0.5 a location had told 0.06-0.13 of the
#: progress for 0.03-0.19), per exemplar pixel analysed and per output pixel collapsed: the
#: shares of the progress (their CPU times over the same levels' queries, median of 3 warm runs
#: at 128^2 -> 256^2, 256^2 -> 512^2 and 512^2 -> 1024^2: the analysis 0.09-0.1, the collapse
#: 0.03).
INDEX_WORK, ANALYSIS_WORK, COLLAPSE_WORK = 150.0, 0.09, 0.036
#: Resident bytes the sampling's fixed batches take beside its tables (its ``CHUNK`` of queries,
#: their candidates and ball searches, the kd-tree's threads; issue 45): 20 MiB traced by
#: tracemalloc and 32-35 MiB resident at 128^2 -> 512^2 and 1024^2, whatever the output's size.
#: Counted as a constant over every phase, it told a 32^2 exemplar to 1024^2 1.63x its growth
#: (the collapse, the peak there, runs after the batches are freed).
SAMPLING_WORKSPACE = 32 << 20
#: Work, in free queries, per block of the coarsest level's quilting, for the progress (issue
#: 40: 0.8-1.3 ms CPU a block against 2.6-3.5 us a query from 256^2 to 512^2, 64^2 to
#: 1024 x 256 and 32^2 to 1024^2, where the quilting, told nothing, took 1 %, 17 % and 55 %).
QUILT_WORK = 330.0


def _per_channel(level: int, top: int, orientations: int) -> int:
    """Values one channel has at a level: K steerable bands and the Laplacian level in between,
    the Laplacian level alone at the finest (never a parent) and at the coarsest (G_S)."""
    return orientations + 1 if 0 < level < top else 1


def pyramid_features(image: np.ndarray, laplacian: LaplacianPyramid, orientations: int,
                     tick=None) -> list[np.ndarray]:
    """Per level, finest first, the (h_l, w_l, F_l) float32 values one location copies, of
    the periodic component of ``image`` (Moisan; analysed from its spectrum,
    :func:`~texsynth.blocks.periodic.periodic_spectrum`).

    Channel by channel: its K oriented steerable bands (levels strictly between the finest and
    the coarsest), then its Laplacian level (``P_l``, or ``G_S`` at the coarsest). The oriented
    bands are the image's steerable pyramid's, analysed from the Laplacian's G_1 (a pyramid of
    the levels from 1 down, :class:`SteerablePyramid`'s ``full``): the full-size image is
    transformed once, for the Laplacian. ``tick()``, if given, after each channel's Laplacian
    and steerable analyses.
    """
    top = laplacian.scales
    steerable = (SteerablePyramid(laplacian.level_shapes[1], top - 1, orientations,
                                  full=laplacian.shape) if top > 1 else None)
    channels = image.shape[2]
    features = [np.empty((*shape, channels * _per_channel(j, top, orientations)), np.float32)
                for j, shape in enumerate(laplacian.level_shapes)]

    def laplacian_levels(c: int) -> np.ndarray | None:
        """Channel c's Laplacian levels into ``features``; its G_1, for the steerable bands."""
        levels = laplacian.analyze(None, spectrum=periodic_spectrum(image[:, :, c]))
        for j, level in enumerate(levels):
            features[j][:, :, (c + 1) * _per_channel(j, top, orientations) - 1] = level
        return laplacian.synthesize(levels, 1) if steerable else None

    # the full-size transforms, channels side by side on the cores (the steerable pyramid
    # reuses its buffers: its analyses run one after the other, each on the cores)
    coarse = run(laplacian_levels, range(channels), tick)
    for c, g1 in enumerate(coarse if steerable else ()):
        for j, level_bands in enumerate(steerable.analyze(g1).bands, start=1):
            n = _per_channel(j, top, orientations)
            for i, band in enumerate(level_bands):
                features[j][:, :, c * n + i] = band
        if tick is not None:
            tick()
    return features


def channel_levels(features, sources, channel, orientations) -> list[np.ndarray]:
    """One output channel's Laplacian levels: that channel's Laplacian column of each level's
    exemplar values, gathered at the source locations."""
    top = len(features) - 1
    levels = []
    for j, (f, s) in enumerate(zip(features, sources, strict=True)):
        n = _per_channel(j, top, orientations)
        levels.append(f.reshape(-1, f.shape[2])[:, channel * n + n - 1][s])
    return levels


def _bilinear(f, s, y, x, k) -> np.ndarray:
    """Rows of ``f`` at an image level whose locations copy from ``s``, read bilinearly at
    (y / 2^k, x / 2^k), wrapping around: the level's sample i sits at 2^k i of the finer one."""
    ha, wa = s.shape
    fy, fx = y / 2.0**k, x / 2.0**k
    y0, x0 = fy.astype(np.int64), fx.astype(np.int64)
    ty = (fy - y0).astype(np.float32)[:, None]
    tx = (fx - x0).astype(np.float32)[:, None]
    y1, x1 = (y0 + 1) % ha, (x0 + 1) % wa
    top_row = f[s[y0, x0]] + tx * (f[s[y0, x1]] - f[s[y0, x0]])
    bottom_row = f[s[y1, x0]] + tx * (f[s[y1, x1]] - f[s[y1, x0]])
    return top_row + ty * (bottom_row - top_row)


def parent_structure(features, sources, level, depth, scale, shape, rows) -> np.ndarray:
    """Parent structures (float32, one row per location) of locations ``rows`` of ``level``.

    ``features[a]`` are the exemplar's level-a values flattened to (N_a, F_a); ``sources[a]``
    maps each location of the image's level a to the flat exemplar location its value was copied
    from (the identity for the exemplar itself); ``scale[a]`` weights level a. Level a = level + k
    is read bilinearly at (y / 2^k, x / 2^k), wrapping around, since its sample i sits at 2^k i.
    """
    y, x = np.divmod(rows, shape[1])
    top = min(level + depth, len(features) - 1)
    return np.concatenate([_bilinear(features[a], sources[a], y, x, a - level)
                           * np.float32(scale[a]) for a in range(level + 1, top + 1)], axis=1)


class ParentSpace:
    """A level's parent structures on their leading principal components (enough for ``energy``
    of the variance of a regular sample of the exemplar's, at most ``max_dims``).

    Projection is linear and a bilinear reading is a weighted mean, so the projected parent
    structure is the sum, over the ancestor levels a, of a bilinear reading of level a's values
    projected beforehand: a location gathers ``dims`` values per ancestor, not all of them.
    """

    def __init__(self, features, level, depth, scale, ex_shape, energy=0.99,
                 max_dims=MAX_DIMS, samples=20000, tick=None):
        self.level = level
        self.ancestors = range(level + 1, min(level + depth, len(features) - 1) + 1)
        flat = [f.reshape(-1, f.shape[2]) for f in features]
        identity = [_identity(f.shape[:2]) if a in self.ancestors else None
                    for a, f in enumerate(features)]
        n = ex_shape[0] * ex_shape[1]
        sample = parent_structure(flat, identity, level, depth, scale, ex_shape,
                                  np.arange(0, n, max(1, n // samples))).astype(np.float64)
        mean = sample.mean(axis=0)
        _, sv, vt = np.linalg.svd(sample - mean, full_matrices=False)
        share = np.cumsum(sv**2) / max(float(np.sum(sv**2)), 1e-300)
        self.dims = min(int(np.searchsorted(share, energy)) + 1, max_dims, len(sv))
        basis = vt[:self.dims].T
        self.offset = (-mean @ basis).astype(np.float32)
        self.projected, start = {}, 0
        for a in self.ancestors:
            block = (basis[start:start + flat[a].shape[1]] * scale[a]).astype(np.float32)
            self.projected[a] = np.empty((len(flat[a]), self.dims), np.float32)
            run(lambda r, a=a, block=block: np.einsum(      # no BLAS (parallel.small_product)
                    "nf,fd->nd", flat[a][r[0]:r[1]], block, out=self.projected[a][r[0]:r[1]]),
                [(i, i + CHUNK) for i in range(0, len(flat[a]), CHUNK)], tick)
            start += flat[a].shape[1]

    def exemplar(self, shape, progress=None) -> np.ndarray:
        """Projected parent structures (float32, (h * w, dims)) of every location of the
        exemplar's level of ``shape``: :meth:`__call__` with the identity sources, computed as
        separable bilinear upsamplings of the projected ancestors (the same arithmetic, bit for
        bit: columns first, then rows), in blocks of rows on the cores; ``progress()`` after
        each block.

        Locations of the same phase (position modulo 2^k) share their interpolation weight and
        read consecutive ancestor samples, so each phase is one strided slice, not a gather;
        a block upsamples only the ancestor rows it reads (on a 12 MP photo's finest level, no
        ancestor is held at the level's width)."""
        h, w = shape
        out = np.empty((h * w, self.dims), np.float32)
        ancestors = [(a - self.level, self.projected[a].reshape(-1, -(-w >> a - self.level),
                                                                  self.dims))
                     for a in self.ancestors]

        def block(rows: slice) -> None:
            total = np.broadcast_to(self.offset, (rows.stop - rows.start, w, self.dims)).copy()
            for k, p in ancestors:
                step, first = 1 << k, rows.start >> k
                r = p[np.arange(first, ((rows.stop - 1) >> k) + 2) % p.shape[0]]
                r1 = np.roll(r, -1, axis=1)                  # sample x0 + 1, wrapping
                c = np.empty((len(r), w, self.dims), np.float32)
                for phase in range(min(step, w)):            # x = x0 2^k + phase
                    n, t = len(range(phase, w, step)), np.float32(phase / step)
                    c[:, phase::step] = r[:, :n] + t * (r1[:, :n] - r[:, :n])
                for y in range(rows.start, min(rows.start + step, rows.stop)):
                    i = (y >> k) - first                     # rows y, y + 2^k, ..: y0 = i, i + 1..
                    n, t = len(range(y, rows.stop, step)), np.float32((y & step - 1) / step)
                    top, bottom = c[i:i + n], c[i + 1:i + n + 1]
                    total[y - rows.start::step] += top + t * (bottom - top)
            out[rows.start * w:rows.stop * w] = total.reshape(-1, self.dims)

        run(block, [slice(a, min(a + EXEMPLAR_ROWS, h)) for a in range(0, h, EXEMPLAR_ROWS)],
            progress)
        return out

    def __call__(self, sources, shape, rows) -> np.ndarray:
        """Projected parent structures (float64, one row per location ``rows`` of an image's
        level of ``shape`` whose levels copy from ``sources``)."""
        y, x = np.divmod(rows, shape[1])
        total = np.broadcast_to(self.offset, (len(rows), self.dims)).copy()
        for a in self.ancestors:
            total += _bilinear(self.projected[a], sources[a], y, x, a - self.level)
        return total.astype(np.float64)


def _identity(shape) -> np.ndarray:
    return np.arange(shape[0] * shape[1], dtype=np.int32).reshape(shape)


class BallSampler:
    """Uniform draws among the ``points`` within ``radius`` of each query, nearest when none.

    Points and queries are low-dimensional (a level's :class:`ParentSpace`), where a kd-tree is
    exact and fast. The ball of a batch of queries is gathered by k-nearest queries bounded by
    the radius, k growing along ``ladder`` only for the queries whose ball is larger, so memory
    stays bounded; balls larger than the ladder are sampled by rejection, whose acceptance is
    then at least ``ladder[-1] / len(points)``. ``eps`` > 0 searches approximately (scipy's
    ``eps``): draws stay inside the ball but may miss some of its points, and the nearest point
    may be one at most ``1 + eps`` times as far.
    """

    ladder = (16, 256, 4096)
    #: neighbours returned by one tree query call (16 bytes each)
    batch = 1 << 18

    def __init__(self, points: np.ndarray, eps: float = 0.0, nearest_eps: float = 0.0,
                 indexed: np.ndarray | None = None):
        self.eps, self.nearest_eps = eps, nearest_eps
        self.points = np.asarray(points)  # float32 kept: differences with float64 queries
        self.indexed = indexed            # are exact; the points the tree holds (None: all)
        # unbalanced, uncompacted nodes: a third of the build time, queries as fast or faster
        self.tree = cKDTree(self.points if indexed is None else self.points[indexed],
                            balanced_tree=False, compact_nodes=False)
        self.radius = 0.0

    def _ids(self, idx: np.ndarray) -> np.ndarray:
        """Point indices of the tree's indices."""
        return idx if self.indexed is None else self.indexed[np.minimum(idx, self.tree.n - 1)]

    def spacing(self, samples: int = 4000) -> float:
        """Median distance from a point the tree holds to its nearest distinct one (on a
        regular sample)."""
        pick = self.tree.data[:: max(1, self.tree.n // samples)]
        dist, _ = self.tree.query(pick, k=min(4, self.tree.n))
        dist = np.where(dist > 0, dist, np.inf).min(axis=1)
        return float(np.median(dist[np.isfinite(dist)])) if np.isfinite(dist).any() else 0.0

    def draw(self, queries: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """One point index per projected query row (int64)."""
        n = len(queries)
        chosen = np.empty(n, np.int64)
        count = np.zeros(n, np.int64)
        todo = np.arange(n)
        # scipy compares squared distances, so a zero bound would find nothing
        bound = max(self.radius * (1 + 1e-12), 1e-150)
        for k in self.ladder:
            k = min(k, self.tree.n)
            larger = []
            for batch in np.array_split(todo, max(1, -(-len(todo) * k // self.batch))):
                dist, idx = self.tree.query(queries[batch], k=k, distance_upper_bound=bound,
                                             eps=self.eps, workers=-1)
                inside = dist.reshape(len(batch), k) <= self.radius
                c = inside.sum(axis=1)
                complete = (c < k) | (k == self.tree.n)
                rows = batch[complete]
                pick = (rng.random(len(rows)) * c[complete]).astype(np.int64)
                chosen[rows] = self._ids(idx.reshape(len(batch), k)[complete, pick])
                count[rows] = c[complete]
                larger.append(batch[~complete])
            todo = np.concatenate(larger) if larger else todo
            if len(todo) == 0:
                break
        if len(todo):
            chosen[todo] = self._reject(queries[todo], rng)
            count[todo] = self.ladder[-1]
        empty = count == 0
        if empty.any():
            chosen[empty] = self._ids(self.tree.query(queries[empty], k=1,
                                                      eps=self.nearest_eps, workers=-1)[1])
        return chosen

    def draw_among(self, queries: np.ndarray, candidates: np.ndarray,
                   rng: np.random.Generator, search: bool = True) -> np.ndarray:
        """One point index per query row, drawn uniformly among its distinct ``candidates``
        (one row of point indices per query) within ``radius``; a query with none inside takes
        its nearest point (within ``1 + nearest_eps``), or draws from the whole ball
        (:meth:`draw`) where that point is inside it; without ``search``, the nearest of its
        candidates (Tong et al. 2002, the k-coherence search's best candidate)."""
        diff = self.points[candidates] - queries[:, None, :]
        d2 = np.einsum("nkd,nkd->nk", diff, diff)
        inside = d2 <= self.radius**2
        for j in range(1, candidates.shape[1]):  # a repeated candidate counts once
            inside[:, j] &= (candidates[:, :j] != candidates[:, j:j + 1]).all(axis=1)
        count = inside.sum(axis=1)
        pick = (rng.random(len(queries)) * count).astype(np.int64)
        column = (np.cumsum(inside, axis=1) > pick[:, None]).argmax(axis=1)
        none = np.flatnonzero(count == 0)
        if not search:
            column[none] = d2[none].argmin(axis=1)
        chosen = candidates[np.arange(len(queries)), column].astype(np.int64)
        if search and len(none):
            # most of these have an empty ball: the nearest point first, the ball where it is in
            # (the approximate nearest may be outside a ball that is not empty: a missed member)
            dist, nearest = self.tree.query(queries[none], k=1, eps=self.nearest_eps,
                                            workers=-1)
            chosen[none] = self._ids(nearest)
            ball = none[dist <= self.radius]
            chosen[ball] = self.draw(queries[ball], rng)
        return chosen

    def _reject(self, queries, rng, tries=64):
        """Uniform points until one falls in the ball: an exact uniform draw from the ball."""
        chosen = np.empty(len(queries), np.int64)
        todo = np.arange(len(queries))
        while len(todo):
            cand = self._ids(rng.integers(0, self.tree.n, (len(todo), tries)))
            diff = self.points[cand] - queries[todo, None, :]
            inside = np.einsum("nkd,nkd->nk", diff, diff) <= self.radius**2
            hit = inside.any(axis=1)
            chosen[todo[hit]] = cand[hit, inside[hit].argmax(axis=1)]
            todo = todo[~hit]
        return chosen


def coherent_candidates(parent_sources, ex_shapes, shape, rows) -> np.ndarray:
    """Per location ``rows`` of a level of ``shape``, the (n, 4) flat exemplar locations that
    continue the sources of its four bilinear parents (the coarser level's ``parent_sources``):
    parent q copied from exemplar location s proposes s's child at the same offset, 2 s + x - 2 q,
    wrapping around the exemplar's level (``ex_shapes``: the exemplar's level, then its parent
    level; Ashikhmin 2001, section 3, with the candidates taken across scales)."""
    w = shape[1]
    hp, wp = parent_sources.shape
    (he, we), (_, wpe) = ex_shapes
    y, x = np.divmod(rows, w)
    columns = []
    for qy in (y // 2, y // 2 + 1):
        for qx in (x // 2, x // 2 + 1):
            s_y, s_x = np.divmod(parent_sources[qy % hp, qx % wp].astype(np.int64), wpe)
            columns.append(((2 * s_y + y - 2 * qy) % he) * we + (2 * s_x + x - 2 * qx) % we)
    return np.stack(columns, axis=1)


def sample_pyramid(features, out_shapes, threshold, depth, rng, progress):
    """Source maps of Algorithm 11.5: per level an (h_l, w_l) int32 array of flat exemplar
    locations. ``features[l]`` are the exemplar's (h_l, w_l, F_l) values; ``out_shapes[l]`` the
    output's level shapes. The coarsest level is a copy of the exemplar's from a random offset,
    or quilted from it where the output's is larger (:func:`quilted`); then every level draws
    among coherent candidates."""
    top = len(features) - 1
    ex_shapes = [f.shape[:2] for f in features]
    sources = [None] * (top + 1)

    work = level_work(ex_shapes, out_shapes)
    ends = np.cumsum([0.0, quilt_work(ex_shapes, out_shapes)] + work[::-1])
    ends /= max(ends[-1], 1.0)                    # nothing to sample: no shares
    hs, ws = ex_shapes[top]
    quilt = quilted(ex_shapes[top], out_shapes[top])
    if quilt:
        block, overlap, radius = _quilt_block(ex_shapes[top], out_shapes[top])
        sources[top] = torus_quilt(features[top], out_shapes[top], block, rng,
                                   overlap=overlap, radius=radius,
                                   tick=lambda f: progress(f * ends[1], "quilting the "
                                                           "coarsest level")).astype(np.int32)
    else:
        oy = _offset(features[top], out_shapes[top][0], rng, features[:top])
        ox = _offset(features[top].transpose(1, 0, 2), out_shapes[top][1], rng,
                     [g.transpose(1, 0, 2) for g in features[:top]])
        ys = (np.arange(out_shapes[top][0]) + oy) % hs
        xs = (np.arange(out_shapes[top][1]) + ox) % ws
        sources[top] = (ys[:, None] * ws + xs[None, :]).astype(np.int32)

    scale = {}
    for level in range(top - 1, -1, -1):
        # the level's index first, its queries after: the sampling's ticks start past its share
        indexed = INDEX_WORK * math.sqrt(ex_shapes[level][0] * ex_shapes[level][1]) / work[level]
        step = progress.span(ends[top - level], ends[top - level + 1])
        message = f"level {level + 1} of {top}: indexing the exemplar"
        for a in range(level + 1, min(level + depth, top) + 1):
            if a not in scale:                            # an ancestor's spread, once
                step(0.0, message)
                scale[a] = 1.0 / (np.sqrt(np.mean(features[a].var(axis=(0, 1)))) + 1e-30)
        space = ParentSpace(features, level, depth, scale, ex_shapes[level],
                            tick=lambda s=step, m=message: s(0.0, m))
        sampler = BallSampler(space.exemplar(ex_shapes[level],
                                             lambda s=step, m=message: s(0.0, m)),
                              eps=EPS, nearest_eps=NEAREST_EPS,
                              indexed=tiled_subset(ex_shapes[level], TREE_POINTS))
        step(indexed, f"level {level + 1} of {top}: sampling")
        sampler.radius = threshold * sampler.spacing()
        h, w = out_shapes[level]
        src = np.empty(h * w, np.int32)
        for start in range(0, h * w, CHUNK):
            rows = np.arange(start, min(start + CHUNK, h * w))
            queries = space(sources, (h, w), rows)
            if quilt or h * w > COHERENT_PIXELS:
                candidates = coherent_candidates(sources[level + 1], ex_shapes[level:level + 2],
                                                 (h, w), rows)
                src[rows] = sampler.draw_among(queries, candidates, rng,
                                               search=h * w < COHERENT_PIXELS)
            else:
                src[rows] = sampler.draw(queries, rng)
            step(indexed + (1.0 - indexed) * (rows[-1] + 1) / (h * w),
                 f"level {level + 1} of {top}")
        sources[level] = src.reshape(h, w)
        del space, sampler               # the next level's table is built without them
    return sources


def _quilt_block(ex_shape, out_shape) -> tuple[int, int, int]:
    """The coarsest level's quilting from the exemplar's of ``ex_shape`` to the output's of
    ``out_shape``: the block's side, its overlap and the radius of the offsets it keeps away
    from (``QUILT_*``, of the exemplar's side, or of a ``CROP_CELLS``-th of the output's where
    the output's is a crop of the exemplar's)."""
    crop = out_shape[0] < ex_shape[0] and out_shape[1] < ex_shape[1]
    side = min(out_shape) // CROP_CELLS if crop else min(ex_shape)
    block = max(4, round(side * QUILT_BLOCK))
    overlap = max(1, round(block * (CROP_OVERLAP if crop else QUILT_OVERLAP)))
    return block, overlap, min(block // 2, int(side * QUILT_RADIUS))


def quilted(ex_shape, out_shape) -> bool:
    """Whether an output's coarsest level of ``out_shape`` is quilted from the exemplar's of
    ``ex_shape`` (it is larger on a side, or smaller on both: a crop, whose wrap would be a
    seam, with blocks of at least ``CROP_BLOCK``) rather than copied whole."""
    return (out_shape[0] > ex_shape[0] or out_shape[1] > ex_shape[1]
            or out_shape[0] < ex_shape[0] and out_shape[1] < ex_shape[1]
            and min(out_shape) // CROP_CELLS >= CROP_BLOCK)


def level_work(ex_shapes, out_shapes) -> list[float]:
    """Each sampled level's work (finest first, the coarsest copied level left out), in free
    queries: its output locations' queries and its exemplar locations' projection and index.
    The progress goes by it: equal shares told a quarter done at a twentieth of the time."""
    quilt = quilted(ex_shapes[-1], out_shapes[-1])   # every level draws coherent ones first
    return [h * w * _query_cost(h * w, quilt) + INDEX_WORK * math.sqrt(ex[0] * ex[1])
            for ex, (h, w) in zip(ex_shapes[:-1], out_shapes[:-1], strict=True)]


def _query_cost(n: float, quilt: bool) -> float:
    """A query's time, in free queries, on a level of ``n`` output locations: among coherent
    candidates (those of every level where the coarsest is quilted), without the ball's search
    from ``COHERENT_PIXELS`` locations on, else in the ball."""
    coherent = quilt or n > COHERENT_PIXELS
    if coherent and n >= COHERENT_PIXELS:
        return NEAREST_COST
    return COHERENT_COST if coherent else 1.0


def quilt_work(ex_shapes, out_shapes) -> float:
    """The coarsest level's quilting's work in free queries (``QUILT_WORK`` a block; none
    where it is copied): its share of the progress, beside :func:`level_work`'s."""
    ex, out = ex_shapes[-1], out_shapes[-1]
    return QUILT_WORK * block_count(out, *_quilt_block(ex, out)[:2]) if quilted(ex, out) else 0.0


def _offset(f: np.ndarray, n: int, rng: np.random.Generator, finer=()) -> int:
    """A random first row for a copy of ``n`` rows of the coarsest level ``f`` (h, w, F),
    wrapping around it. When ``n`` is not a multiple of h the copy's own wrap joins row
    o + n - 1 to row o: the draw is among the tenth of the rows o whose row o + n (the copy's
    continuation) is nearest to row o, so the output's wrap continues the exemplar. Nearest
    on every level: ``finer`` are the finer levels, the k-th coarser by 2^k (the copy's rows
    o 2^k .. (o + n) 2^k there, the finer levels following the coarsest copy coherently),
    each level's squared differences over its variance on those rows."""
    h = f.shape[0]
    if n % h == 0:
        return int(rng.integers(0, h))
    rows = np.arange(h)
    gap = np.zeros(h)
    for k, g in enumerate((f, *finer[::-1])):
        start = g[(rows << k) % g.shape[0]]            # the level's variance from these rows
        gap += ((g[((rows + n) << k) % g.shape[0]] - start) ** 2).mean(axis=(1, 2)) \
            / max(float(start.var()), 1e-30)
    return int(rng.choice(np.argsort(gap, kind="stable")[:max(1, h // 10)]))


def tiled_subset(shape, points: int, tile: int = TILE) -> np.ndarray | None:
    """Flat locations of a level of ``shape`` in tiles of ``tile`` x ``tile``, every k-th tile
    (k prime to the tiles of a row: a sheared lattice of tiles over the whole level) so that
    about ``points`` are kept; None (all) for a level of fewer than twice ``points``."""
    h, w = shape
    k = (h * w) // points
    if k < 2:
        return None
    down, across = -(-h // tile), -(-w // tile)
    while math.gcd(k, across) != 1:
        k += 1
    kept = (np.arange(down)[:, None] * across + np.arange(across)) % k == 0
    return np.flatnonzero(np.repeat(np.repeat(kept, tile, axis=0)[:h], tile, axis=1)[:, :w])


def de_bonet(exemplar, width, height, rng, progress, threshold=0.5, depth=3, scales=4,
             orientations=4):
    """Synthesize (height, width, C) from ``exemplar``: each pyramid level copied, coarse to
    fine, from exemplar locations whose parent structure is near the output's (see the module
    notes).

    Parameters
    ----------
    exemplar : float32 array (H, W, C)
        The sample, validated by ``texsynth.synthesize``.
    width, height : int
        The output size, larger or smaller than the exemplar.
    rng, progress : numpy.random.Generator, texsynth.progress.Progress
        The seeded generator and the progress reporter ``texsynth.synthesize`` makes.
    threshold : float
        How far a parent structure may be from the output's, in typical nearest-neighbour
        distances: 0 copies the exemplar, above about 1 structure dissolves (and matching
        slows).
    depth : int
        Coarser levels in the parent structure.
    scales : int
        Pyramid levels (capped by exemplar and output sizes); the coarsest is copied, or
        quilted where the output is larger or a crop of a larger photo.
    orientations : int
        Oriented subbands per level (K).

    Returns
    -------
    numpy.ndarray
        float32 (height, width, C), periodic, clipped to the exemplar's range.

    References
    ----------
    Forsyth & Ponce, section 11.3.3, Algorithm 11.5 and exercise 1; De Bonet 1997;
    Ashikhmin 2001, section 3 and Tong et al. 2002 (k-coherence at production sizes);
    Moisan 2011 (the periodic component analysed).

    Examples
    --------
    >>> import numpy as np, texsynth
    >>> photo = np.random.default_rng(0).random((32, 32, 3), dtype=np.float32)
    >>> out = texsynth.synthesize(photo, 32, 32, method="de_bonet", seed=1, scales=2, depth=1)
    >>> out.shape, bool(photo.min() <= out.min() and out.max() <= photo.max())
    ((32, 32, 3), True)
    """
    levels = pyramid_depth(exemplar.shape, width, height, scales)
    pyr_exemplar = LaplacianPyramid(exemplar.shape[:2], levels)
    pyr_output = LaplacianPyramid((height, width), levels)
    work = [ANALYSIS_WORK * exemplar.shape[0] * exemplar.shape[1],
            sum(level_work(pyr_exemplar.level_shapes, pyr_output.level_shapes))
            + quilt_work(pyr_exemplar.level_shapes, pyr_output.level_shapes),
            COLLAPSE_WORK * width * height]         # the progress' shares (level_work)
    analysed, sampled = work[0] / sum(work), (work[0] + work[1]) / sum(work)
    progress(0.0, "analysing the exemplar")
    features = pyramid_features(exemplar, pyr_exemplar, orientations,
                                lambda: progress(0.0, "analysing the exemplar"))
    progress(analysed, "exemplar analysed")
    sources = sample_pyramid(features, pyr_output.level_shapes, threshold, depth, rng,
                             progress.span(analysed, sampled))
    out = np.empty((height, width, exemplar.shape[2]), np.float32)
    coarsest, tiled = features[-1].shape[:2], pyr_output.level_shapes[-1]
    for c in range(exemplar.shape[2]):
        progress(sampled + (1 - sampled) * c / exemplar.shape[2], "collapsing the pyramid")
        levels = channel_levels(features, sources, c, orientations)
        if not quilted(coarsest, tiled) and (tiled[0] % coarsest[0] or tiled[1] % coarsest[1]):
            # a crop of the exemplar's coarsest level, whose wrap would be a seam
            levels[-1] = periodic_component(levels[-1])
        out[:, :, c] = pyr_output.synthesize(levels)
    if levels == 0:
        # too thin for a pyramid (a side under 8): the "coarsest level" is an exemplar crop,
        # whose wrap is a jump; its periodic component (Moisan) tiles
        out = periodic_component(out)
    return np.clip(out, exemplar.min(axis=(0, 1)), exemplar.max(axis=(0, 1)), out=out)


def _indexed(shape, levels: int) -> list[int]:
    """Exemplar locations each level's kd-tree holds (:func:`tiled_subset` beyond
    ``TREE_POINTS``), finest first."""
    counts, (h, w) = [], shape[:2]
    for _ in range(levels):
        subset = h * w // max(1, h * w // TREE_POINTS) if h * w >= 2 * TREE_POINTS else h * w
        counts.append(subset)
        h, w = (h + 1) // 2, (w + 1) // 2
    return counts


def _memory(shape, width, height, params):
    """The exemplar's level values, held throughout (per exemplar pixel 4 C bytes at the finest
    level, 4 C (K + 1) / 4 per coarser level of a quarter the size: about 4 C (1 + (K + 1) / 3)),
    and the largest of three phases. Analysing: two channels' transforms side by side, 38 bytes
    per exemplar pixel (measured). Sampling the finest level: per exemplar pixel its projected
    parent structure (float32) and its ancestors' (8 bytes); per indexed location, its kd-tree;
    per output pixel, the int32 source maps; and the matching's fixed batches
    (``SAMPLING_WORKSPACE``). Collapsing: per output pixel, the output, the source maps, one
    channel's Laplacian levels and its spectra (the batches freed). On the 12 MP photo and its
    1024 crop to 2048^2: 0.95-0.99 and 0.98-1.00 of the measured growth of resident memory (3
    runs each)."""
    k, c = params["orientations"], shape[2]
    exemplar = shape[0] * shape[1]
    held = 4 * c * (1 + (k + 1) / 3) * exemplar
    sources = 4 * 4 / 3 * width * height
    tree = min(exemplar, 2 * TREE_POINTS)
    analysing = 38 * exemplar
    sampling = (4 * MAX_DIMS + 8) * exemplar + 80 * tree + sources + SAMPLING_WORKSPACE
    collapsing = (4 * c + 4 * 4 / 3 + 16) * width * height + sources
    return held + max(analysing, sampling, collapsing)


def _cost(shape, width, height, params):
    """Seconds on the reference machine (``texsynth.budget``). Per output location, a
    parent-structure query of a kd-tree (about ``depth`` ancestors of K + 1 values per channel),
    about 0.56 times that on a level with coherent candidates, 0.42 where it searches no ball
    (:func:`_query_cost`; level l holds 3/4 of 4^-l of the pyramid's locations); per exemplar pixel,
    its periodic component, Laplacian pyramid and projected parent structures; per indexed location,
    the tree's build. Fitted on a 1024^2 crop and the 12 MP photo to 2048^2 (14.0 and 21.6 s at
    factor 0.36; the query term had predicted under half of the crop's time); the per-pixel term
    then scaled by 0.73, as the 12 MP photo's CPU time beyond its crop's fell (6.4 -> 4.7 s, then
    8.6 -> 5.8 s, medians of alternating runs on a loaded machine) once its finest level's table was
    made by slices: not refitted on a quiet machine. Per block of the coarsest level's quilting,
    ``QUILT_COST`` (issue 45: a 32^2 exemplar to 1024^2 was predicted 0.44-0.47 of its time, the
    square rows 1.0-1.2)."""
    h, w, c = shape
    k, depth = params["orientations"], params["depth"]
    spread = (1.0 + params["threshold"]) ** 2
    pixels, locations = width * height, 0.0
    levels = pyramid_depth(shape, width, height, params["scales"])
    quilt = quilted(*_coarsest(shape, width, height, levels))
    for level in range(16):
        n = pixels * 4.0**-level
        locations += 0.75 * n * _query_cost(n, quilt)
    return (0.03 + 1.5e-6 * locations * spread * (1 + depth * (k + 1) * c / 15)
            + 3.6e-7 * h * w * c + 3.1e-8 * sum(_indexed(shape, levels)) * depth * (k + 1) * c
            + QUILT_COST * _quilt_blocks(shape, width, height, levels))


def _coarsest(shape, width, height, levels: int):
    """The exemplar's and the output's coarsest level shapes, halved as
    ``LaplacianPyramid``'s."""
    ex, out = shape[:2], (height, width)
    for _ in range(levels):
        ex, out = tuple((n + 1) // 2 for n in ex), tuple((n + 1) // 2 for n in out)
    return ex, out


def _quilt_blocks(shape, width, height, levels: int) -> int:
    """Blocks the coarsest level's quilting places (none where it is copied)."""
    ex, out = _coarsest(shape, width, height, levels)
    return block_count(out, *_quilt_block(ex, out)[:2]) if quilted(ex, out) else 0


METHOD = register(Method(
    name="de_bonet",
    label="De Bonet",
    description="Copy each pyramid coefficient from an exemplar location whose coarser-scale "
                "parents match (De Bonet 1997): keeps structure that spans scales, such as "
                "spots on lines; low thresholds copy, high ones mix",
    function=de_bonet,
    params=(
        Param("threshold", float, 0.5, "How far a parent structure may be from the output's, "
              "in typical nearest-neighbour distances: 0 copies the exemplar, above about 1 "
              "structure dissolves (and matching slows)", 0.0, 2.0),
        Param("depth", int, 3, "Coarser levels in the parent structure", 1, 8),
        Param("scales", int, 4, "Pyramid levels (capped by exemplar and output sizes); the "
              "coarsest is copied, or quilted where the output is larger or a crop of a larger "
              "photo", 1, 8),
        Param("orientations", int, 4, "Oriented subbands per level (K)", 1, 8),
    ),
    min_exemplar=16,
    memory=_memory,
    cost=_cost,
))
