"""A tile set for render-time anti-repetition: Wang tiles made from a photo, in one atlas.

Cohen, Shade, Hiller & Deussen 2003, "Wang Tiles for Image and Texture Generation", section 3:
every edge colour of the horizontal edges, and every one of the vertical edges, is a
diamond-shaped sample of the photo centred on the edge; a tile with edge colours ``(n, e, s,
w)`` is its four diamonds' inner halves (the triangles between its edges and its centre), so
two tiles that share an edge colour show the same diamond across it, and neighbours match
whatever tiles surround them. The diagonals, where one tile's triangles meet, are hidden by
image quilting's minimum error boundary cut (Efros & Freeman 2001, 2.1;
``texsynth.blocks.quilting``). Every tile pixel is a photo pixel: the tile set comes with its
position map, which makes the other maps of a material (roughness, normal) into the same tiles.

- **Diamonds in phase**: each diamond is placed where its sides agree best with the diamonds
  of the other direction already placed, in the four quarters of a tile where they meet
  (the quilting patch choice, Efros & Freeman 2001, 2.1: at random among the placements
  within ``TOLERANCE`` of the best), so on a brick wall every diamond's courses and joints
  line up with every other's. The SSD is the full-resolution one (block means of ``f`` x
  ``f`` above ``SEARCH_SIDE``, refined within ``f``) plus ``TONE`` times that of 16 x 16 block
  means: at full resolution the grain outweighs a tone, and diamonds of unlike tone showed
  as a diagonal lattice of lighter and darker patches (concrete pavers). No two diamonds
  overlap by more than a quarter.
- **Tile side**: about half the photo's shorter side, at the side in ``[3/4, 1]`` of that at
  which the photo best repeats itself (its autocorrelation at a shift of one side across and
  down): on regular photos a whole number of courses and bricks, so the diamonds of both
  directions can all be in phase.
- **Cuts**: each quarter of a tile (between its centre and one corner) holds one cut, a path
  across the quarter's anti-diagonals (a step of the path is a step right or down, so it can
  follow a mortar joint in either direction), pinned at the corner and kept within ``BAND``
  of the diagonal; the quarter's outer rows and columns keep their own edge's diamond.
- **Interiors** (issue 41): with the diamonds alone, 2 colours give 2 diamonds a direction and a
  shift of one cell shows the same diamond half the time (rendered 8 x 8, the autocorrelation
  peaked at 0.33-0.53 at one cell); so each tile's middle is its own patch of the photo, as
  Cohen et al. fill a tile's interior from the sample: a ``t`` x ``t`` window placed where
  it agrees best with the tile on the square ring of Chebyshev radii ``INTERIOR`` (times
  ``t``) around the tile's centre (the quilting patch choice, in phase with the courses as
  the diamonds are), away from the tile's own diamonds and from the other tiles' interiors
  (``INTERIOR_SPACING``, halved while the photo has no room for one more), cut in along the
  ring by a closed minimum error boundary cut on the ring unrolled (angle, radius); a band
  along every edge keeps its diamond, so neighbours still match. The ring is square and near
  the edges so that the middle, not the shared diamonds, holds most of the tile (a round
  ring of radii 0.22-0.44 left the diamonds two thirds of it, and their repeats at whole-cell
  shifts peaked at 0.27-0.47 even with 3 colours).
- **Courses** (issue 41): where the photo has courses (``texsynth.blocks.rhythm``:
  :func:`~texsynth.blocks.rhythm.course_period`, and their period to a fraction of a pixel and
  local phase, :func:`~texsynth.blocks.rhythm.course_phase`), the tile side is a whole number
  of courses (within ``PHASE`` of one) and every diamond and interior is taken where the
  photo's courses are in phase with the first diamond's (the source row of tile row ``i`` at
  the same place in its course, within ``PHASE`` of a course), so every cell continues its
  neighbours' courses: the SSD alone kept the courses at the photo's resolution and not
  across cells seen at 4 texels a pixel (the brick wall's row means' spread fell from 0.051 to
  0.019 and its render's anisotropy to 0.58 of the plain one's).
- **Atlas** (the tiles read by a shader, Wei 2004's complete set picked by hashed edges): the
  ``colours**4`` tiles in a ``colours**2`` square grid, each with a ``gutter`` of pixels on
  every side copied from the diamond beyond that edge, what the neighbour shows there (so a
  linear or mipmapped read at a tile's edge sees its neighbour's content); the tile of edge
  colours ``(n, e, s, w)`` sits in slot row ``n * colours + s`` and column ``w * colours + e``
  (:meth:`WangTiles.slot`).

Deviations, one line each:

- the diamonds' places are searched (above), not taken anywhere in the photo: only diamonds
  in phase keep a regular photo's rows whole across the cuts;
- a complete set of ``colours**4`` tiles picked per cell from hashed edge colours (Wei 2004),
  not Cohen et al.'s 8 tiles laid in scanline order (a shader cannot see its neighbours' tiles);
- the interiors' cut is a closed path of one radius per angle (a star-shaped patch), not a
  graph cut;
- the gutters' corner squares continue the north and south diamonds (the diagonal neighbour's
  tile is unknown there);
- the edge colours come from an integer hash of the edge's coordinates and the seed
  (:func:`edge_colours`, the two values of ``blend.vertex_offsets`` at the edge's first
  lattice point); Blender's node group uses its White Noise texture there: both are uniform,
  so the tiles differ, not their statistics.

References
----------
Cohen, Shade, Hiller & Deussen 2003, 3 (diamond samples, tiles from their halves); Efros &
Freeman 2001, 2.1 (patch choice, minimum error boundary cut); Wei 2004 (a complete Wang tile set
in one texture, each cell's tile from hashed edge colours).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft

from .. import budget, validation
from ..blocks.periodic import periodic_component
from ..blocks.quilting import Search, block_means, min_error_path
from ..blocks.rhythm import course_period, course_phase
from .blend import vertex_offsets

__all__ = ["WangTiles", "wang_tiles", "wang_tiling", "wang_tiling_positions", "edge_colours",
           "default_tile", "photo_use", "predict_tiles_memory", "MAX_ATLAS", "COLOURS"]

#: Largest atlas side (pixels): 8192 keeps it a texture every GPU takes.
MAX_ATLAS = 8192
#: Edge colours per direction by default: 3 (81 tiles). With 2, a shift of whole cells shows the
#: same diamond on half the edges and the autocorrelation of an 8 x 8 render peaked at
#: 0.27-0.40 beyond 24 px; with 3 at 0.16-0.28 (the four benchmark photos, numpy tiling).
COLOURS = 3
#: Smallest tile side accepted.
MIN_TILE = 16
#: The cut's reach from the diagonal, as a fraction of the tile side (along a row or column).
BAND = 1 / 4
#: Efros & Freeman's error tolerance: placements within (1 + TOLERANCE) x the best SSD.
TOLERANCE = 0.1
#: Two diamonds' centres are at least this fraction of the tile side apart (city-block
#: distance): diamonds are city-block discs, so they overlap by at most a quarter.
SPACING = 1 / 2
#: The diamonds are searched on block means of the photo when its shorter side is above this
#: (pixels): the joints' phase needs the full resolution (blocks a tile's 32nd across put
#: pavers out of phase by a fifth of their length).
SEARCH_SIDE = 1024
#: The tone's weight in the diamonds' search, and its block side (pixels): the SSD of the
#: block means, each block counted for its pixels, TONE times.
TONE, TONE_BLOCK = 4.0, 16
#: The square ring (Chebyshev radii as fractions of the tile side) in which a tile's interior
#: patch is cut in: within it the tile's middle is its own; outside it, a band of at least
#: 0.05 of the tile along every edge, the diamonds' (the edges are half a tile from the
#: centre).
INTERIOR = (0.34, 0.45)
#: A tile's interior window is at least this fraction of the tile from the tile's own diamonds
#: and from every other interior (Chebyshev distance of the windows' corners; from the other
#: interiors halved while no window is that far: the photo has room for about 25).
INTERIOR_SPACING = 1 / 4
#: The courses' phase tolerance, as a fraction of a course: a tile side this close to a whole
#: number of courses; every copy's course phase this close to the first diamond's.
PHASE = 1 / 16

# Tile pixel (i, j) of the triangle of role X reads the photo at c_X + (i, j) + _OFFSET[X],
# c_X the centre of its diamond: N and S are halves of horizontal-edge diamonds, W and E of
# vertical-edge ones.
_N, _E, _S, _W = range(4)
# Each quarter of a tile: (horizontal role, vertical role, flip rows, flip columns) seen as the
# north-west quarter, where the cut runs from the corner (0, 0) to the centre.
_QUARTERS = ((_N, _W, False, False), (_N, _E, False, True), (_S, _W, True, False),
             (_S, _E, True, True))


def _offsets(t: int) -> np.ndarray:
    h = t // 2
    return np.array([(0, -h), (-h, -t), (-t, -h), (-h, 0)])  # N, E, S, W


@dataclass(frozen=True)
class WangTiles:
    """A Wang tile set and its atlas.

    ``atlas`` float32 (A, A, C), ``A = colours**2 * (tile + 2 * gutter)``, top row first;
    ``positions`` int32 (A, A, 2): the photo pixel (row, col) of every atlas pixel
    (``texsynth.apply_positions(positions, other_map)`` gives another map's atlas);
    ``tile`` and ``gutter`` in pixels; ``colours`` per edge direction; ``centres`` int (2,
    colours, 2): the photo pixel (row, col) at the centre of each diamond, horizontal edges'
    first; ``photo_shape`` (H, W) of the photo.
    """

    atlas: np.ndarray
    positions: np.ndarray
    tile: int
    gutter: int
    colours: int
    centres: np.ndarray
    photo_shape: tuple

    @property
    def step(self) -> int:
        """Pixels from one slot to the next: ``tile + 2 * gutter``."""
        return self.tile + 2 * self.gutter

    def slot(self, n, e, s, w):
        """The atlas pixel (row, col) of the first pixel (top-left, inside the gutter) of the
        tile with edge colours north ``n``, east ``e``, south ``s``, west ``w``: row ``(n * C
        + s) * step + gutter``, column ``(w * C + e) * step + gutter``; works on arrays.

        Examples
        --------
        >>> tiles = wang_tiles(np.zeros((64, 64)), tile=16, colours=2, gutter=2)
        >>> [int(v) for v in tiles.slot(1, 0, 1, 0)], tiles.atlas.shape
        ([62, 2], (80, 80, 1))
        """
        c, step, g = self.colours, self.step, self.gutter
        return (np.asarray(n) * c + s) * step + g, (np.asarray(w) * c + e) * step + g


def default_tile(shape, colours: int = COLOURS, gutter: int = 8) -> int:
    """The tile side used when none is given, before the fit to the photo's period: half the
    photo's shorter side (even), at most what keeps the atlas within :data:`MAX_ATLAS` and
    the diamonds and gutters inside the photo.

    Examples
    --------
    >>> default_tile((1024, 768, 3))
    384
    """
    side = min(shape[:2])
    t = min(side // 2, MAX_ATLAS // colours ** 2 - 2 * gutter, side - 2 * gutter - 1)
    return max(0, t - t % 2)


def _courses_off(side, course):
    """How far (in courses) ``side`` pixels are from a whole number of ``course`` pixels."""
    return np.abs(side / course - np.rint(side / course))


def _fit_tile(grey: np.ndarray, t0: int, f: int, course: float | None = None) -> int:
    """The even side in [3/4 t0, t0] (a multiple of ``2 f``) at which ``grey`` best repeats
    itself: the largest mean of its autocorrelation at that shift down and across (the
    periodic component's, Moisan 2011); with a ``course`` (pixels), among the sides within
    ``PHASE`` of a whole number of courses (the largest such side below 3/4 t0 if none is in
    the range)."""
    sides = np.arange(t0 - t0 % (2 * f), int(np.ceil(0.75 * t0)) - 1, -2 * f)
    if course is not None:
        whole = _courses_off(sides, course) <= PHASE
        if not whole.any():
            below = np.arange(sides[-1], MIN_TILE - 1, -2 * f)
            below = below[_courses_off(below, course) <= PHASE]
            return int(below[0]) if len(below) else int(sides[0])
        sides = sides[whole]
    g = grey[::f, ::f].astype(np.float64)
    p = periodic_component(g).astype(np.float64)
    p -= p.mean()
    a = sfft.irfft2(np.abs(sfft.rfft2(p)) ** 2, s=p.shape)
    if a[0, 0] <= 1e-12 * p.size:
        return int(sides[0])
    score = [a[(t // f) % p.shape[0], 0] + a[0, (t // f) % p.shape[1]] for t in sides]
    return int(sides[int(np.argmax(score))])  # ties: the largest side


def _band(t: int) -> np.ndarray:
    """The north-west quarter's pixels within BAND of its diagonal (the SSD's weight)."""
    h = t // 2
    i, j = np.indices((h, h))
    return (np.abs(j - i) <= BAND * t).astype(np.float32)


def _quarter_view(a: np.ndarray, q: int, t: int) -> np.ndarray:
    """Quarter ``q`` of a (t, t, ...) tile array, flipped to look like the north-west one."""
    h = t // 2
    _, _, flip_rows, flip_cols = _QUARTERS[q]
    part = a[h:, :] if flip_rows else a[:h, :]
    part = part[:, h:] if flip_cols else part[:, :h]
    return part[::-1 if flip_rows else 1, ::-1 if flip_cols else 1]


class _Placer:
    """Chooses the diamonds' centres: each where its sides agree with the other direction's
    diamonds already placed (the quilting patch choice), searched on block means of ``f`` x
    ``f`` (1 up to SEARCH_SIDE) and refined at full resolution within ``f`` pixels."""

    def __init__(self, photo: np.ndarray, t: int, gutter: int):
        h, w = photo.shape[:2]
        self.photo, self.t, self.f = photo, t, _search_step((h, w))
        self.lo = t // 2 + gutter  # centres from lo to hi - 1 keep the diamond's box and
        self.hi = (h - t // 2 - gutter, w - t // 2 - gutter)  # its gutters inside the photo
        self.band = _band(t)
        self.search = Search(block_means(photo, self.f) if self.f > 1 else photo)
        self.tone = Search(block_means(photo, TONE_BLOCK))
        self.offset = _offsets(t)
        self.course = None  # (course pixels, phase map at every f-th column), see in_phase
        self.phase0 = None  # the first diamond's course phase

    def phase(self, d, rows, cols):
        """The course phase (in courses) of a copy that shows photo row ``d + i`` at tile row
        ``i``, read at photo (``rows``, ``cols``): ``d / P + theta / 2 pi``."""
        course, theta = self.course
        return d / course + theta[rows, cols // self.f] / (2 * np.pi)

    def in_phase(self, d, rows, cols):
        """Whether those copies, centred at (``rows``, ``cols``), are within ``PHASE`` of a
        course of the first diamond's there and a quarter tile above and below (a photo's
        courses are seldom evenly spaced; all True without courses or before the first
        diamond)."""
        ok = np.ones(np.broadcast_shapes(np.shape(d), np.shape(rows), np.shape(cols)), bool)
        if self.course is None or self.phase0 is None:
            return ok
        for k in (-1, 0, 1):
            e = self.phase(d, np.clip(rows + k * (self.t // 4), 0, self.photo.shape[0] - 1),
                           cols) - self.phase0
            ok &= np.abs(e - np.rint(e)) <= PHASE
        return ok

    def centre_in_phase(self, direction, rows, cols):
        """:meth:`in_phase` for diamonds of ``direction`` centred at (``rows``, ``cols``): a
        vertical edge's diamond shows row ``c - t / 2`` at tile row 0, a horizontal one row
        ``c`` (its north half; its south half ``c - t``, a whole number of courses on)."""
        return self.in_phase(rows - direction * (self.t // 2), rows, cols)

    def grid(self) -> tuple[np.ndarray, np.ndarray]:
        """The candidate centres' rows and columns: multiples of ``f`` from ``lo``."""
        start = -(-self.lo // self.f) * self.f
        return np.arange(start, self.hi[0], self.f), np.arange(start, self.hi[1], self.f)

    def _pairs(self, direction, others):
        """For each quarter where a diamond of ``direction`` meets one of ``others``: the
        other diamond's photo there (h, h, C), the band's weights, and where the quarter's
        first pixel is in the photo relative to this diamond's centre."""
        h = self.t // 2
        for centre in others:
            for hr, vr, flip_rows, flip_cols in _QUARTERS:
                mine, theirs = (hr, vr) if direction == 0 else (vr, hr)
                origin = np.array([h if flip_rows else 0, h if flip_cols else 0])
                y, x = np.asarray(centre) + self.offset[theirs] + origin
                mask = self.band[::-1 if flip_rows else 1, ::-1 if flip_cols else 1]
                yield self.photo[y:y + h, x:x + h], mask, self.offset[mine] + origin

    def coarse(self, direction, others) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The summed SSD (on block means of ``f`` x ``f``) of a diamond of ``direction``
        (0 horizontal, 1 vertical) centred at each candidate of :meth:`grid` against the
        ``others``, plus ``TONE`` times that of their tones (16 x 16 block means)."""
        f = self.f
        rows, cols = self.grid()
        total = np.zeros((len(rows), len(cols)))
        for template, mask, shift in self._pairs(direction, others):
            if f > 1:
                template, mask = block_means(template, f), block_means(mask[:, :, None], f)[
                    :, :, 0]
            ssd = self.search.ssd(template, mask)
            d = (shift + (rows[0], cols[0])) // f  # my quarter's block at the first candidate
            total += ssd[d[0]:d[0] + len(rows), d[1]:d[1] + len(cols)]
        b = TONE_BLOCK
        for template, mask, shift in self._pairs(direction, others):
            ssd = self.tone.ssd(block_means(template, b),
                                block_means(mask[:, :, None], b)[:, :, 0])
            # each candidate's quarter at its nearest block
            py = np.minimum((shift[0] + rows + b // 2) // b, ssd.shape[0] - 1)
            px = np.minimum((shift[1] + cols + b // 2) // b, ssd.shape[1] - 1)
            total += TONE * b * b * ssd[py[:, None], px[None, :]]
        return total, rows, cols

    def refine(self, direction, others, centre) -> tuple[int, int]:
        """The centre within ``f`` pixels of ``centre`` with the least full-resolution SSD."""
        f, h = self.f, self.t // 2
        y0 = np.clip(centre[0] - f, self.lo, self.hi[0] - 1)
        x0 = np.clip(centre[1] - f, self.lo, self.hi[1] - 1)
        y1 = min(centre[0] + f, self.hi[0] - 1)
        x1 = min(centre[1] + f, self.hi[1] - 1)
        total = 0.0
        for template, mask, shift in self._pairs(direction, others):
            py, px = shift + (y0, x0)
            window = self.photo[py:py + y1 - y0 + h, px:px + x1 - x0 + h]
            total = total + Search(window).ssd(template, mask)
        rows, cols = np.ix_(np.arange(y0, y0 + total.shape[0]), np.arange(x0, x0 + total.shape[1]))
        ok = self.centre_in_phase(direction, rows, cols)
        if ok.any():
            total = np.where(ok, total, np.inf)
        dy, dx = np.unravel_index(np.argmin(total), np.shape(total))
        return int(y0 + dy), int(x0 + dx)

    def choose(self, direction, others, used, rng) -> tuple[int, int]:
        """A centre at random among those within TOLERANCE of the best, at least ``SPACING``
        tiles from the ``used`` ones (the first diamond anywhere), refined."""
        if others:
            total, rows, cols = self.coarse(direction, others)
        else:
            rows, cols = self.grid()
            total = np.zeros((len(rows), len(cols)))
        far = np.ones(total.shape, bool)
        for y, x in used:
            far &= np.abs(rows[:, None] - y) + np.abs(cols[None, :] - x) >= SPACING * self.t
        both = far & self.centre_in_phase(direction, rows[:, None], cols[None, :])
        far = both if both.any() else far
        if far.any():
            total[~far] = np.inf
        near = np.flatnonzero(total <= total.min() * (1 + TOLERANCE))
        k = near[rng.integers(len(near))]
        centre = int(rows[k // len(cols)]), int(cols[k % len(cols)])
        if others and self.f > 1:
            centre = self.refine(direction, others, centre)
        if self.course is not None and self.phase0 is None:
            self.phase0 = self.phase(centre[0] - direction * (self.t // 2), *centre)
        return centre


def _cut(e: np.ndarray, t: int) -> np.ndarray:
    """The minimum error cut through the north-west quarter (t/2, t/2) of error ``e``
    between the vertical role (west, below-left) and the horizontal one (north): True where
    the west diamond is kept. Anti-diagonal ``s`` (pixels ``i + j = s``) is cut at row
    ``k_s``: its pixels of row ``i >= k_s`` are west's. The north edge stays north's, the west
    edge west's, the quarter's inner column north's and inner row west's (its neighbours
    there), and the cut keeps within ``BAND * t`` of the diagonal (``|s - 2 k| <= BAND t``)."""
    h = t // 2
    s, k = np.meshgrid(np.arange(2 * h - 1), np.arange(h), indexing="ij")
    j = s - k
    lo = np.maximum.reduce([np.ones_like(s[:, 0]), s[:, 0] - h + 2,
                            np.ceil((s[:, 0] - BAND * t) / 2).astype(int)])
    hi = np.minimum.reduce([s[:, 0], np.full_like(s[:, 0], h - 1),
                            np.floor((s[:, 0] + BAND * t) / 2).astype(int)])
    lo = np.minimum(lo, hi)
    allowed = (k >= lo[:, None]) & (k <= hi[:, None]) & (j >= 0) & (j < h)
    cost = np.where(allowed, e[k, np.clip(j, 0, h - 1)], np.inf)
    path = min_error_path(cost)
    i, jj = np.indices((h, h))
    return i >= path[i + jj]


def _tile_labels(photo, centres, colours_nesw, t, offset) -> np.ndarray:
    """Which triangle (N, E, S, W) each pixel of the tile ``colours_nesw`` keeps."""
    n, e, s, w = colours_nesw
    c = (centres[0][n], centres[1][e], centres[0][s], centres[1][w])
    i, j = np.indices((t, t))
    h, w = photo.shape[:2]
    # Each role's content over the whole tile; only its own quarters are read, the rest is
    # clipped to the photo.
    content = [photo[np.clip(c[r][0] + offset[r][0] + i, 0, h - 1),
                     np.clip(c[r][1] + offset[r][1] + j, 0, w - 1)] for r in range(4)]
    labels = np.empty((t, t), np.int8)
    for q, (hr, vr, _, _) in enumerate(_QUARTERS):
        a, b = _quarter_view(content[hr], q, t), _quarter_view(content[vr], q, t)
        d = a - b
        west = _cut(np.einsum("ijc,ijc->ij", d, d), t)
        view = _quarter_view(labels, q, t)
        view[...] = np.where(west, vr, hr)
    return labels


def _ring(t: int):
    """The ring's samples around the centre of a (t, t) tile, square (Chebyshev radii, see
    ``INTERIOR``): per angle (rows) and radius (columns) the nearest pixel (row, col) arrays,
    and each tile pixel's angle bin and Chebyshev radius."""
    r0, r1 = INTERIOR[0] * t, INTERIOR[1] * t
    angles = int(np.ceil(8 * r1))
    theta = 2 * np.pi * (np.arange(angles) + 0.5) / angles
    radius = np.arange(np.ceil(r0), np.floor(r1) + 1)
    sin, cos = np.sin(theta), np.cos(theta)
    reach = np.maximum(np.abs(sin), np.abs(cos))  # a ray's Chebyshev radius per unit length
    c = (t - 1) / 2
    rows = np.clip(np.rint(c + radius[None, :] * (sin / reach)[:, None]), 0, t - 1).astype(int)
    cols = np.clip(np.rint(c + radius[None, :] * (cos / reach)[:, None]), 0, t - 1).astype(int)
    i, j = np.indices((t, t)) - c
    bins = (np.floor(np.mod(np.arctan2(i, j), 2 * np.pi) / (2 * np.pi) * angles)
            .astype(int) % angles)
    return rows, cols, radius, bins, np.maximum(np.abs(i), np.abs(j))


def _interior(placer, a, tile_positions, avoid, rng):
    """A tile's middle from its own window of the photo: the window's corner (row, col) and
    the (t, t) mask of the pixels it takes (see the module's Interiors)."""
    t, f = placer.t, placer.f
    rows, cols, radius, bins, dist = placer.ring
    content = a[tile_positions[..., 0], tile_positions[..., 1]]
    mask = ((dist >= INTERIOR[0] * t) & (dist <= INTERIOR[1] * t)).astype(np.float32)
    if f > 1:
        ssd = placer.search.ssd(block_means(content, f), block_means(mask[:, :, None], f)[
            :, :, 0])
    else:
        ssd = placer.search.ssd(content, mask)
    ys, xs = np.arange(ssd.shape[0]) * f, np.arange(ssd.shape[1]) * f

    def far(corners, spacing):
        """The candidates at least ``spacing`` tiles (Chebyshev) from every one of
        ``corners``."""
        ok = np.ones(ssd.shape, bool)
        for y, x in corners:
            ok &= (np.abs(ys[:, None] - y) >= spacing * t) \
                | (np.abs(xs[None, :] - x) >= spacing * t)
        return ok

    # the tile's own diamonds always (the window that agrees best is where they came from);
    # the other interiors as far as the photo has room: the spacing halved until some is
    own = far(avoid[:4], INTERIOR_SPACING)
    spacing = INTERIOR_SPACING
    while spacing * t >= f and not (own & far(avoid[4:], spacing)).any():
        spacing /= 2
    allowed = own & far(avoid[4:], spacing) if spacing * t >= f else own
    h, w = placer.photo.shape[:2]
    phased = allowed & placer.in_phase(ys[:, None], np.minimum(ys + t // 2, h - 1)[:, None],
                                       np.minimum(xs + t // 2, w - 1)[None, :])
    allowed = phased if phased.any() else allowed
    if allowed.any():
        ssd = np.where(allowed, ssd, np.inf)
    near = np.flatnonzero(ssd <= ssd.min() * (1 + TOLERANCE) + 1e-12)
    k = near[rng.integers(len(near))]
    corner = int(ys[k // ssd.shape[1]]), int(xs[k % ssd.shape[1]])
    window = a[corner[0]:corner[0] + t, corner[1]:corner[1] + t]
    d = window[rows, cols] - content[rows, cols]
    path = min_error_path(np.einsum("...c,...c->...", d, d), closed=True)
    return corner, dist <= radius[path][bins]


def predict_tiles_memory(shape, tile: int | None = None, colours: int = COLOURS,
                         gutter: int = 8) -> float:
    """Peak bytes of :func:`wang_tiles` on a photo of ``shape`` (H, W[, C]) with tiles of
    ``tile`` pixels (default: 7/8 of :func:`default_tile`, the middle of the range [3/4, 1] of it
    that the fit to the photo's period picks from, so the atlas term is within 1.3x of any side
    the fit picks; the most it can be read 1.58x the peak on the 2048 setts photo): the atlas
    and its positions (float32 channels and two int32 a pixel), the search's float64 copy and
    spectra (8 C + 16 bytes a photo pixel, fitted) and an interior's search beside them (24 +
    8 C more), one slot's int64 index arrays (four) and the photo's float32 copy (made when it
    comes as bytes). tracemalloc's peak on float32 photos from 256 x 320 to 1024 x 1024, grey
    and RGB, 2 and 3 colours: 1.1-1.4 x below.

    Examples
    --------
    >>> predict_tiles_memory((1024, 1024, 3)) < 2**30
    True
    """
    h, w = shape[:2]
    c = shape[2] if len(shape) > 2 else 1
    t = 7 * default_tile(shape, colours, gutter) // 8 if tile is None else tile
    f = _search_step((h, w))
    a = colours ** 2 * (t + 2 * gutter)
    return float(a * a * (4 * c + 8) + (h // f) * (w // f) * (40 + 16 * c)
                 + (t + 2 * gutter) ** 2 * 32 + h * w * c * 4)


def _search_step(shape) -> int:
    return max(1, -(-min(shape[:2]) // SEARCH_SIDE))


def _sample_step(shape) -> int:
    """Every f-th pixel of every f-th row for the period fit: the least power of two that
    brings the photo to at most 2^20 pixels (as ``blocks.period``)."""
    f = 1
    while shape[0] * shape[1] > (1 << 20) * f * f:
        f *= 2
    return f


def wang_tiles(photo, *, tile: int | None = None, colours: int = COLOURS, gutter: int = 8,
               seed: int = 0, progress: Callable[[float, str], object] | None = None
               ) -> WangTiles:
    """A complete set of Wang tiles made from ``photo``, in one atlas with gutters.

    Parameters
    ----------
    photo : array (H, W) or (H, W, C), C in 1, 3, 4
        Floats as they are, uint8/uint16 scaled to [0, 1].
    tile : int, optional
        Tile side in pixels (even); default: fitted to the photo's period near
        :func:`default_tile` (half the shorter side).
    colours : int
        Edge colours per direction, 2 to 4: ``colours**4`` tiles.
    gutter : int
        Pixels around each tile in the atlas, copied from its neighbours' side, 0 to tile / 4
        (with the fitted tile, at most a quarter of it).
    seed : int
        Same inputs and seed give bit-identical tiles.
    progress : callable(fraction, message), optional
        Returning ``False`` cancels (``texsynth.Cancelled``).

    Returns
    -------
    WangTiles

    References
    ----------
    Cohen et al. 2003, 3; Efros & Freeman 2001, 2.1; Wei 2004 (see the module's docstring).

    Examples
    --------
    >>> photo = np.random.default_rng(0).random((96, 96, 3)).astype(np.float32)
    >>> tiles = wang_tiles(photo, tile=32, seed=1)
    >>> tiles.atlas.shape, tiles.positions.dtype
    ((432, 432, 3), dtype('int32'))
    >>> bool((photo[tuple(np.moveaxis(tiles.positions, 2, 0))] == tiles.atlas).all())
    True
    """
    a = validation.image(photo, what="photo", min_side=MIN_TILE + 2)
    seed = validation.seed(seed)
    colours = validation.whole(colours, "colours", 2, 4)
    h, w, c = a.shape
    gutter = validation.whole(gutter, "gutter (pixels)", 0)
    largest = default_tile((h, w), colours, gutter)
    if largest < MIN_TILE:
        need = max(2 * MIN_TILE, MIN_TILE + 2 * gutter + 1)
        raise ValueError(f"photo is {w} x {h} pixels, too small: tiles of at least {MIN_TILE} "
                         f"pixels with a gutter of {gutter} need at least {need} pixels a side")
    if tile is not None:
        tile = validation.whole(tile, "tile (pixels)", MIN_TILE, largest)
        if tile % 2:
            raise ValueError(f"tile must be an even number of pixels, got {tile}")
    if tile is not None and gutter > tile // 4:
        raise ValueError(f"gutter must be at most a quarter of the tile ({tile // 4} pixels), "
                         f"got {gutter}")
    budget.admit(f"Wang tiles from the {w} x {h} photo", memory_advice="smaller tiles",
                 peak=predict_tiles_memory(a.shape, tile or largest, colours, gutter))
    rng, report = budget.start(seed, progress, "Wang tiles: the tile side")
    period = course_period(a)
    course, theta = course_phase(a, period, largest // 2, _search_step((h, w))) \
        if period is not None else (None, None)
    if tile is None:
        tile = _fit_tile(a.mean(axis=2), largest, _sample_step((h, w)), course)
        gutter = min(gutter, tile // 4)
    t = tile

    placer = _Placer(a, t, gutter)
    if course is not None and _courses_off(t, course) <= PHASE:
        placer.course = course, theta
    placer.ring = _ring(t)
    centres: list[list[tuple[int, int]]] = [[], []]
    used: list[tuple[int, int]] = []
    for k in range(2 * colours):
        direction = k % 2  # horizontal, vertical, horizontal, ...
        report(0.05 + 0.45 * k / (2 * colours), "Wang tiles: placing the diamonds")
        centre = placer.choose(direction, centres[1 - direction], used, rng)
        centres[direction].append(centre)
        used.append(centre)
    centres_arr = np.array(centres)

    step = t + 2 * gutter
    size = colours ** 2 * step
    positions = np.empty((size, size, 2), np.int32)
    offset = _offsets(t)
    i, j = np.indices((step, step)) - gutter
    gutter_role = np.where(i < 0, _N, np.where(i >= t, _S, np.where(j < 0, _W, _E)))
    count = colours ** 4
    interiors: list[tuple[int, int]] = []
    for index, nesw in enumerate(np.ndindex(*(colours,) * 4)):
        report(0.5 + 0.5 * index / count, "Wang tiles: cutting the tiles")
        role = gutter_role.copy()
        role[gutter:gutter + t, gutter:gutter + t] = _tile_labels(a, centres_arr, nesw, t,
                                                                  offset)
        diamond = np.array([centres_arr[0][nesw[0]], centres_arr[1][nesw[1]],
                            centres_arr[0][nesw[2]], centres_arr[1][nesw[3]]])
        origin = diamond + offset  # per role: the photo pixel of tile pixel (0, 0)
        n, e, s, w_ = nesw
        r0 = (n * colours + s) * step
        c0 = (w_ * colours + e) * step
        slot = positions[r0:r0 + step, c0:c0 + step]
        slot[..., 0] = origin[role, 0] + i
        slot[..., 1] = origin[role, 1] + j
        inner = slot[gutter:gutter + t, gutter:gutter + t]
        corner, kept = _interior(placer, a, inner, [*origin, *interiors], rng)
        interiors.append(corner)
        ii, jj = np.indices((t, t))
        inner[kept] = np.stack([corner[0] + ii, corner[1] + jj], -1)[kept]
    atlas = a[positions[:, :, 0], positions[:, :, 1]]
    report(1.0, "Wang tiles: done")
    return WangTiles(atlas, positions, t, gutter, colours, centres_arr, (h, w))


def photo_use(tiles: WangTiles) -> np.ndarray:
    """The share of a Wang tiling's pixels that show each photo pixel, float64 (H, W) summing
    to 1: every tile (gutters left out) counted once, as the hashed edge colours pick every
    tile equally often (Wei 2004). The diamonds and interiors are windows inside the photo,
    so its middle shows most and its outermost rows and columns least or never: what a
    Tile Set render is to be compared with (a plain render shows every photo pixel alike).

    References
    ----------
    Cohen et al. 2003, 3; Wei 2004 (see the module's docstring).

    Examples
    --------
    >>> photo = np.random.default_rng(0).random((96, 96)).astype(np.float32)
    >>> use = photo_use(wang_tiles(photo, tile=32, gutter=2))
    >>> use.shape, round(float(use.sum()), 6), bool(use[48, 48] > use[0, 0])
    ((96, 96), 1.0, True)
    """
    g, t, step = tiles.gutter, tiles.tile, tiles.step
    inner = tiles.positions.reshape(tiles.colours ** 2, step, tiles.colours ** 2, step, 2)[
        :, g:g + t, :, g:g + t].reshape(-1, 2)
    count = np.bincount(np.ravel_multi_index(inner.T, tiles.photo_shape),
                        minlength=int(np.prod(tiles.photo_shape)))
    return (count / len(inner)).reshape(tiles.photo_shape)


def edge_colours(x, y, colours: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """The colours of the horizontal edge from lattice point (x, y) to (x + 1, y) and of the
    vertical edge from (x, y) to (x, y + 1) (integer arrays, ``y`` up): ``floor(u * colours)``
    for the two uniform values ``u`` of ``blend.vertex_offsets`` at (x, y) and the seed.

    Examples
    --------
    >>> h, v = edge_colours(np.arange(4), np.zeros(4, int), 2, seed=5)
    >>> h.shape, sorted(set(h.tolist()) | set(v.tolist())) <= [0, 1]
    ((4,), True)
    """
    u = vertex_offsets(np.stack(np.broadcast_arrays(x, y), -1), seed)
    return (np.minimum(np.floor(u[..., 0] * colours), colours - 1).astype(np.int64),
            np.minimum(np.floor(u[..., 1] * colours), colours - 1).astype(np.int64))


def _cell_counts(cells) -> tuple[int, int]:
    if isinstance(cells, (tuple, list)) and len(cells) == 2:
        return (validation.whole(cells[0], "cells (across)", 1, validation.MAX_SIDE),
                validation.whole(cells[1], "cells (down)", 1, validation.MAX_SIDE))
    n = validation.whole(cells, "cells", 1, validation.MAX_SIDE)
    return n, n


def wang_tiling_positions(tiles: WangTiles, width: int, height: int, *, cells=4, seed: int = 0,
                          wrap: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """:func:`wang_tiling` and its position map, int32 (height, width, 2): the photo pixel
    (row, col) each output pixel shows (``texsynth.apply_positions``).

    Examples
    --------
    >>> import texsynth
    >>> photo = np.random.default_rng(0).random((64, 64)).astype(np.float32)
    >>> tiles = wang_tiles(photo, tile=16, gutter=2)
    >>> image, at = wang_tiling_positions(tiles, 64, 64, cells=4)
    >>> bool((texsynth.apply_positions(at, photo) == image[:, :, 0]).all())
    True
    """
    if not isinstance(tiles, WangTiles):
        raise ValueError(f"tiles must be the WangTiles of wang_tiles(), got {type(tiles)}")
    width, height = validation.size(width, height)
    cx, cy = _cell_counts(cells)
    seed = validation.seed(seed)
    if not isinstance(wrap, bool):
        raise ValueError(f"wrap must be True or False, got {wrap!r}")
    validation.check_memory(float(width) * height * (4 * tiles.atlas.shape[2] + 8 * 8),
                            f"A Wang tiling of {width} x {height} pixels", "a smaller size")
    # Texture coordinates of the pixel centres, v up (Blender's UV): cells across each.
    u = (np.arange(width) + 0.5) / width * cx
    v = (height - np.arange(height) - 0.5) / height * cy
    ix, iy = np.floor(u).astype(np.int64), np.floor(v).astype(np.int64)
    fu, fv = u - ix, v - iy
    x, y = np.meshgrid(ix, iy)
    right, up = x + 1, y + 1
    if wrap:
        x, y, right, up = x % cx, y % cy, right % cx, up % cy
    c = tiles.colours
    south, west = edge_colours(x, y, c, seed)
    north = edge_colours(x, up, c, seed)[0]
    east = edge_colours(right, y, c, seed)[1]
    row0, col0 = tiles.slot(north, east, south, west)
    t = tiles.tile
    col = np.minimum(np.floor(fu * t).astype(np.int64), t - 1)
    row = np.minimum(np.floor((1.0 - fv) * t).astype(np.int64), t - 1)
    rows, cols = row0 + row[:, None], col0 + col[None, :]
    return tiles.atlas[rows, cols], tiles.positions[rows, cols]


def wang_tiling(tiles: WangTiles, width: int, height: int, *, cells=4, seed: int = 0,
                wrap: bool = True) -> np.ndarray:
    """A ``width`` x ``height`` image laid with the Wang tiles: what the node group renders.

    Texture space has ``cells`` cells across (an int, or (across, down)); pixel ``(y, x)``
    (top row first) is at ``u = (x + 0.5) / width * cells_x``, ``v = (height - y - 0.5) /
    height * cells_y`` (``v`` up, as Blender's UV). Cell ``(X, Y) = floor(u, v)`` has edge
    colours south ``h(X, Y)``, north ``h(X, Y + 1)``, west ``v(X, Y)``, east ``v(X + 1, Y)``
    from :func:`edge_colours`; it shows that tile's pixel ``(row, col) = (floor((1 - frac(v))
    T), floor(frac(u) T))``, the closest texel. With ``wrap`` the lattice points are taken
    modulo the cells, so the image itself tiles.

    Parameters
    ----------
    tiles : WangTiles
        From :func:`wang_tiles`.
    width, height : int
        Output size in pixels (``cells * tiles.tile`` shows the tiles at the photo's scale).
    cells : int or (int, int)
        Cells across the output (and down).
    seed : int
        Picks the edge colours.
    wrap : bool
        Edge colours periodic over the output (it tiles); False: as the node group, which
        repeats nowhere.

    Returns
    -------
    float32 (height, width, C)

    References
    ----------
    Wei 2004 (the tile of a cell from its hashed edge colours); Cohen et al. 2003, 2.

    Examples
    --------
    >>> photo = np.random.default_rng(0).random((64, 64, 3)).astype(np.float32)
    >>> out = wang_tiling(wang_tiles(photo, tile=16, gutter=2), 64, 32, cells=(4, 2))
    >>> out.shape, out.dtype
    ((32, 64, 3), dtype('float32'))
    """
    return wang_tiling_positions(tiles, width, height, cells=cells, seed=seed, wrap=wrap)[0]
