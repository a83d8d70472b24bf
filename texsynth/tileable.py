"""Make a photo itself tile: keep its pixels, quilt a band across the wrap from its own patches.

Seen rolled by half its size, a photo's wrap-around seam is a cross through the middle. Each
arm of the cross (a band of ``band`` pixels: a horizontal arm along the width, a vertical arm
along the height) is covered by image quilting, Efros & Freeman 2001, "Image quilting for
texture synthesis and transfer" (``texsynth.blocks.quilting``):

- 2.1, patch choice: square-ish photo patches are laid along the arm in two rows, each
  overlapping its neighbour by a quarter patch, the ring around the arm closing on its first.
  The first row covers ``band / 4`` kept rows before the band, the band's first half and a
  quarter band past the seam; the second row the rest, back over the first by half the band.
  Each patch is chosen by its SSD with what is already fixed where it overlaps it: the kept
  photo beyond the seam's side it continues (the rows outside the band and the band's outer
  quarter), its neighbour along the arm, and (second row) the first row: at random among the
  ``CANDIDATES`` best within ``TOLERANCE`` of the best;
- 2.1, minimum error boundary cut: each patch meets its neighbour along a DP path through
  their overlap; the first row meets the kept photo along a DP path in the band's outer
  quarter, the second row the first row in the band's middle half and the kept photo in the
  band's other outer quarter: each a closed loop around the torus;
- the vertical arm is quilted over the photo with the horizontal arm in, so at the crossing it
  continues the horizontal arm;
- along each arm the row of patches is a ring that closes halfway along it: the closing patch,
  the one fitted to neighbours on both sides, lies where the photo beyond the band is one
  continuous piece, and the crossing, where the photo beyond the band jumps (the wrap) and
  where the horizontal arm's middle cut has absorbed a course, lies on the overlap of two
  consecutive patches, the later one fitted to the earlier and cut against it. (Closed at the
  crossing, one patch had to fit both sides of that jump: on the brick wall photo a short
  column of broken bricks above the crossing in 3 of 6 seeds, steps in the pavers' joints.)

The wrap line lies inside whole copied patches: it is no seam any more. What remains are the
cuts, placed where the two sides agree; the middle cut absorbs what no single patch could,
such as courses of bricks whose count does not fit the photo's height (a course a little
shorter, cut along a joint). Pixels are copied whole, never averaged: the band is as sharp as
the photo.

What no cut can hide is a difference of level: a photo lit from one side is brighter along one
edge than along the other, and the pieces, continuing each side, still meet with a step. So
the cross is then replaced by Pérez, Gangnet & Blake 2003, "Poisson image editing", 2-3
(guided interpolation, ``texsynth.blocks.poisson``): the function whose gradient is the
pieces' own (taken piece by piece: a cut contributes no gradient) and which equals the kept
photo at the band's outer edges, on the torus. The level difference is spread smoothly over
the band's width; the pieces' detail is kept as it is. The position map says which photo
pixel each piece pixel came from; :func:`follow` makes another map of the material tile the
same way (its pixels moved, and the same correction from its own gradients).

Deviations, one line each:
- two rows of patches across the band (Efros & Freeman fill a raster of patches; the two rows
  are its two-row case, each row continuing its own side of the seam);
- the candidates are searched on the photo's block means (``f`` x ``f`` blocks, a patch about
  ``COARSE`` blocks across), the best few refined at full resolution within ``f`` pixels;
- the patches come from the part of the photo that is kept (farther than ``band / 2`` from its
  edges): edge defects inside the band (a ledge, a vignette) are replaced, never copied;
- a source window more than half covered by one already used is not chosen again (no visible
  repeats along the band);
- the overlap is matched on the colours and on the local contrast (``_contrast``: the root of
  ``CONTRAST`` x the variance within ``CONTRAST_BOX`` pixels; on the search's grid, within a
  block, ``_coarse``; the refinement of a grid's candidates on the colours alone): by SSD
  alone a flat patch fits any textured overlap best (two windows of gravel differ by twice
  its variance, ground and gravel by once), and a mixture's band (smooth ground, rough
  gravel) was quilted from the ground, a soft cross (seam ratio 0.27-0.69 over 6 seeds of a
  256 crop); with ``CONTRAST`` above 1 the gravel's own patches fit it best;
- where the photo has courses across the horizontal arm, the cut between neighbouring
  patches is barred from the pixels on a line across the arm in either (``_across``: a head
  joint, unlike the rest of its row in the overlap) where it can pass beside them (Efros &
  Freeman cut on the SSD alone): by it, the cut ran along a head joint, where the two agree
  best, and broke it where they were a pixel apart (the generated wall 480 x 448: dead-end
  ratio 0.99-1.15 over seeds 0-5, now 0.97-1.09; seeds 6-23 1 over 1.15, was 3);
- so is the middle cut between the arm's two rows of patches, where the courses run on in
  phase across the wrap, from the pixels of such lines that run ``d / 2`` rows or more
  across the arm (``_runs``: unopened, the grain's odd pixels barred 8-22 % of every row):
  where the wrap is a lattice step only within ``PHASE`` (the pavers' centre 512: 4 courses
  shift the head joints 2 Q + 10 px), the two rows hold a course's head joints that far
  apart, and crossing one the cut kept both, a stub beside the joint below the bed joint at
  the crossing (dead-end ratio 1.18 at seed 0, now 1.02; seeds 0-5 at most 1.07); beside
  them, it runs along the bed joint;
- rows of the band whose mean colour (across the arm) is like none of the rows farther than
  ``band`` from the photo's edges are not matched (Efros & Freeman weigh the whole overlap
  alike): on the brick wall photo a dark ledge along the bottom edge drew patches that
  squashed a course to continue it, and the cuts kept pieces of it; nor may the cuts with
  the photo keep such a row (they pass between it and the band's middle where they can);
- the horizontal arm's patches are quilted right to left, the vertical arm's top to bottom:
  the method prefers neither direction; on the granite setts photo the stones at the
  crossing stayed whole in 3-4 of 6 seeds right to left, 1 of 6 left to right (the patches
  left of the crossing, fitted before those right of it, cut off a joint of the kept photo
  there), and bottom to top made the generated brick wall's wrap read 0.76-0.80 in phase in
  2 of 6 seeds;
- where the photo has courses down its rows (``texsynth.blocks.rhythm``: a period of its row
  means), the horizontal arm's patches are taken a whole number of periods (within
  ``PHASE``) from the rows they continue (copies in phase with the lattice, Liu, Collins &
  Tsin 2004): matched on a quarter band of rows, a patch out of phase left
  out the bed joint the rows below them hold (the concrete pavers' centre 512: two courses
  merged into one paver at the wrap); the vertical arm's column means (a running bond's half
  brick) are no lattice step, and phased they broke the test bricks' wrap (0.80 in phase);
  where the photo's height is a whole number of periods (within ``PHASE``), the courses run
  on in phase across the wrap and the vertical arm's patches are taken a whole number of
  periods (within a block) from the rows where they go: free, the patch at the crossing
  left the bed joint at the wrap broken (the pavers' centre 512, a 14 px gap or step);
  where it is not (the brick walls: a part of a course left at the crossing), as before;
  without courses (gravel, a mixture, noise) the patches are chosen as before;
- where the photo's height is no whole number of periods, the horizontal arm's two rows of
  patches are out of phase with each other (each continues its own side's courses) and the
  middle cut, which absorbs the difference, stays in the quarter band before the seam (Efros
  & Freeman cut anywhere in the overlap): crossing the seam to and fro, it made the wrap line
  read lines at two places in the courses, the seam ratio in phase 0.86-1.23 over seeds 0-11
  on the brick wall's centre 512 (now 0.81-1.11);
- where the courses' elements stand in a lattice (``texsynth.blocks.rhythm.bond``: head
  joints a period ``Q`` apart along a course, shifted ``s`` a course on) and the photo's
  height is one of its steps (whole courses, their shift whole elements), both arms' patches
  are copied by whole lattice steps, ``n`` courses and ``n s + k Q`` columns, within a block
  on the search's grid and exactly at full resolution (Liu, Collins & Tsin 2004's lattice;
  copies by a lattice vector continue every joint):
  free along the courses, the vertical arm lost a head joint (a paver twice as long) or held
  two a few pixels apart, and within ``PHASE`` the horizontal arm's bed joint stepped 12 px
  between patches (the concrete pavers' centre 512, dead-end ratio 1.11-1.24 over 6 seeds,
  now 0.79-1.09); both rows of the vertical arm read the lattice from the photo left of the
  wrap, whose width is no whole number of elements (from either side, the two rows' head
  joints lay 9 px apart and the middle cut, running beside them, kept both or neither);
- no blending of the pieces: the cuts and the correction stay within the band, so every pixel
  farther than ``band / 2`` from the photo's edges is unchanged;
- the correction covers the whole cross, the photo's own pixels within the band included (Pérez
  et al. replace one pasted region), and is clipped to the photo's range in each channel;
- across a cut, the guidance is the one of the two pieces' own gradients nearer the difference
  shown (Pérez et al. 3 take one image's, or the larger: mixing gradients): a joint beside the
  cut stays, an edge of what the cut left out (a ledge beyond it) is not brought back;
- where the line just beyond the band is unlike the photo's inner lines (``_unlike``, in a
  channel by itself: a ledge, a shadow along the edge), the band keeps its step to it in that
  channel: matched there, the band faded into the ledge's dark over 1000-2500 pixels (the
  deep ledge tests).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from . import budget, metrics, validation
from .blocks import poisson, rhythm
from .blocks.joints import joint_mask, luma
from .blocks.parallel import serial_blas
from .blocks.quilting import Search, block_means, min_error_path

__all__ = ["make_tileable", "make_tileable_positions", "follow", "default_band", "predict",
           "check", "tiles"]

#: Narrowest band accepted, and the default band's least width (pixels).
MIN_BAND, DEFAULT_MIN = 8, 16
#: Smallest photo side accepted.
MIN_SIDE = 16
#: Largest share of the photo a band may change (the issue asks at least half unchanged).
MAX_CHANGED = 0.5
#: As fractions of the band: the kept rows matched beyond it on either side, its outer rows
#: where the cuts with the photo go, and the half-overlap of the two rows of patches.
CONTEXT, CUT, MIDDLE = 1 / 4, 1 / 4, 1 / 4
#: Overlap of neighbouring patches along an arm, as a fraction of the patch.
OVERLAP = 1 / 4
#: Patch side in blocks at the search scale.
COARSE = 32
#: Placements refined at full resolution for each patch.
CANDIDATES = 4
#: Efros & Freeman's error tolerance: candidates within (1 + TOLERANCE) x the best SSD.
TOLERANCE = 0.1
#: The scale (pixels) of the local contrast matched beside the colours, and its weight: its
#: standard deviation over the photo's (the colours' together).
CONTRAST_BOX, CONTRAST = 5, 1.5
#: A row is unlike the photo when, in some channel, its mean colour is farther than this many
#: robust standard deviations (1.4826 x the median absolute deviation of the inner rows'
#: means) from every inner row's.
UNLIKE = 1.5
#: Fewest inner rows to judge by; with fewer, every row is matched.
MIN_INNER = 8
#: A photo already tiles when its wrap reads as its own lines: the seam ratio in phase within
#: 1 +- TILES (``metrics.seam_ratio_in_phase``; a photo's interior crosses read 0.85-1.2).
TILES = 0.1
#: Where the photo has courses across an arm (``texsynth.blocks.rhythm``), the patches' rows
#: are a whole number of periods from the lines they continue, within this share of a period;
#: the row means are read on every k-th column, about RHYTHM_SIDE of them.
PHASE, RHYTHM_SIDE = 1 / 8, 1024
#: Where the photo has courses across the horizontal arm, the cuts between its neighbouring
#: patches pass beside the pixels farther than this many robust standard deviations from their
#: row's median (a head joint in the overlap).
LINE = 2.0
#: Where the lattice is regular (``rhythm.bond``), the patches are in phase with it within a
#: block on the search's grid, and exactly (within this many pixels) at full resolution.
FINE_PHASE = 0
#: Where the lattice is regular (``rhythm.bond``: the candidates are its few copies a lattice
#: step away, alike in colour), they are compared on the photo's joints as well (issue 41):
#: the joints of half width ``JOINT_SIGMA`` pixels that ``Joints`` reads in the photo (at full
#: resolution), each pixel of the mask where the patch's joint differs from the template's
#: costing ``JOINT`` x the photo's colour variance (its channels' summed). On the concrete
#: pavers' centre 512 (joints read at half width 3), seeds 6-41: the dead-end ratio at most
#: 1.13, mean 0.93 (by the colours alone up to 1.43, mean 1.14, 17 of 36 over 1.15); half
#: widths 1.5 and 2.8: 5 and 3 of 36 over; weights 30 and 300: none.
JOINT_SIGMA, JOINT = 2.0, 100.0


def tiles(photo: np.ndarray) -> bool:
    """Does ``photo`` (H, W[, C]) tile as it is? Its wrap as seamless as its own lines: the
    seam ratio in phase (luminance) within ``1 +- TILES``.

    Examples
    --------
    >>> x = np.random.default_rng(0).random((64, 64))  # white noise tiles; with a ramp, not
    >>> tiles(x), tiles(x + np.linspace(0, 1, 64)[:, None])
    (True, False)
    """
    return abs(metrics.seam_ratio_in_phase(luma(photo)) - 1.0) <= TILES


def default_band(shape) -> int:
    """The band width used when none is given: an eighth of the shorter side, at least
    ``DEFAULT_MIN`` pixels, and never so wide that more than half of the photo would change."""
    side = min(shape[:2])
    return int(min(max(side // 8, DEFAULT_MIN), _widest(shape)))


def _widest(shape) -> int:
    """The widest band that changes at most ``MAX_CHANGED`` of an (h, w) photo:
    changed = b (h + w) - b^2 <= MAX_CHANGED h w."""
    h, w = shape[:2]
    return int(((h + w) - np.sqrt((h + w) ** 2 - 4 * MAX_CHANGED * h * w)) / 2)


@dataclass(frozen=True)
class _Layout:
    """Where the patches go, for an (h, w) photo and a band of ``b`` pixels.

    Across an arm, ``side`` rows: ``m`` kept rows, the band (``top`` rows before the seam,
    its outer ``c`` rows on either side where the cuts with the photo go), ``m`` kept rows;
    the two rows of patches overlap on the ``d`` rows either side of the seam. Along the arm,
    patches overlap by ``overlap``; ``f`` is the search's block size, ``e`` the photo's edge
    left out of the sources."""

    h: int
    w: int
    b: int

    @property
    def top(self) -> int:
        return self.b // 2

    @property
    def m(self) -> int:
        return min(int(self.b * CONTEXT), (min(self.h, self.w) - self.b) // 2)

    @property
    def side(self) -> int:
        return self.b + 2 * self.m

    @property
    def d(self) -> int:
        return max(1, int(self.b * MIDDLE))

    @property
    def c(self) -> int:
        return max(1, int(self.b * CUT))

    @property
    def e(self) -> int:
        return max(0, min(self.b // 2, (min(self.h, self.w) - self.side) // 2))

    @property
    def overlap(self) -> int:
        return max(2, int(self.side * OVERLAP))

    @property
    def f(self) -> int:
        return max(1, self.side // COARSE)

    def starts(self, length: int) -> np.ndarray:
        """The patches' first pixels along an arm of ``length``, and the first one again plus
        ``length``: the first patch begins halfway along the arm, and an overlap between two
        patches is centred on the crossing of the arms (position 0)."""
        n = max(2, -(-length // (self.side - self.overlap)))
        at = np.rint(np.arange(n + 1) * length / n).astype(int)
        return -(self.overlap // 2) + at + at[n // 2]


class _Source:
    """The photo (or its transpose, for the vertical arm) as the patches' source: the search
    for the patch that fits a template, and a patch's pixels and photo positions."""

    def __init__(self, image: np.ndarray, contrast: np.ndarray | None,
                 coarse: np.ndarray | None, f: int, e: int, swap: bool,
                 period: int | None = None, along: int | None = None,
                 bond: tuple[int, int] | None = None, joints: np.ndarray | None = None,
                 joint: float = 0.0):
        self.image, self.f, self.e, self.swap = image, f, e, swap
        # The photo's joint mask (float32, photo coordinates; None: the colours alone) and
        # the cost of a pixel where the patch's differs from the template's (``JOINT``).
        self.joints, self.joint = joints, joint
        # The courses' period across the arm (``texsynth.blocks.rhythm``), None without one,
        # and along it (the vertical arm's, where the wrap is in phase: :func:`_along`); the
        # courses' bond (``rhythm.bond``: the head joints' period and shift a course on).
        self.period, self.along, self.across = period, along, image.shape[0] + 2 * e
        self.bond = bond
        # Searched at full resolution (f == 1): the photo's contrast (:func:`_contrast`), as
        # the photo is (templates read it at their pixels' positions), and as this source is.
        self.contrast, self.own = contrast, None
        if f == 1:
            ours = contrast.T if swap else contrast
            self.own = ours[e:ours.shape[0] - e, e:ours.shape[1] - e, None]
        self.search = Search(coarse if f > 1 else np.concatenate([image, self.own], axis=2))

    def _excluded(self, shape, ph, pw, used) -> np.ndarray:
        """Placements (on the search's grid) whose window is more than half covered by a used
        window, in each direction."""
        f = self.f
        y = np.arange(shape[0])[:, None] * f + self.e
        x = np.arange(shape[1])[None, :] * f + self.e
        out = np.zeros(shape, bool)
        for uy, ux, uh, uw in used:
            if self.swap:
                uy, ux, uh, uw = ux, uy, uw, uh
            out |= (np.abs(y - uy) * 2 < min(ph, uh)) & (np.abs(x - ux) * 2 < min(pw, uw))
        return out

    def _out_of_phase(self, ys, xs, origin, start, frame=None, tol=None) -> np.ndarray:
        """Placements (on the search's grid) whose rows are not a whole number of course
        periods (within ``PHASE``, at least a block) from the photo lines ``origin``
        onwards that the patch continues, or whose columns not a whole number of periods
        along the arm (within a block) from the photo line ``start`` where the patch goes:
        all False without a period. ``ys``, ``xs``: the placements' rows and columns in this
        source; ``tol``: the tolerance in pixels where there is a bond (default a block)."""
        tol = self.f if tol is None else tol
        out = np.zeros((len(ys), len(xs)), bool)
        # The shifts of a placement from where its patch goes: across the arm, along it.
        across = ys + self.e - origin
        along = xs + self.e - start
        if self.along is not None:
            r = along % self.along
            out[:, np.minimum(r, self.along - r) > tol] = True
        courses = self.along if self.swap else self.period
        if self.bond is not None and courses is not None:
            # Whole elements along the courses too: a shift of n courses (rows) and n s + k Q
            # columns maps the lattice onto itself (rhythm.bond).
            q, s = self.bond
            if frame is not None:  # the bond read from another line than the courses
                across = across + origin - frame
            rows, cols = (along, across) if self.swap else (across, along)
            n = np.rint(rows / courses).astype(np.int64)
            r = (cols[None, :] - n[:, None] * s) % q  # (rows, columns) of the photo's shift
            off = np.minimum(r, q - r) > tol
            out |= off.T if self.swap else off
        if self.period is None:
            return out
        r = across % self.period
        off = np.minimum(r, self.period - r)
        # A lattice in both directions is regular: its courses are placed within a block too.
        out[off > (tol if self.bond is not None else max(self.f, PHASE * self.period))] = True
        return out

    def choose(self, template, at, mask, rng, used, origin=0, start=0, frame=None
               ) -> tuple[int, int]:
        """The patch origin, in this source's coordinates, for ``template`` (its pixels from
        the photo positions ``at``) weighted by ``mask``: the ``CANDIDATES`` best placements
        on the search's grid (apart from each other, none more than half covered by a
        ``used`` window, in phase with the courses across the arm from the photo line
        ``origin`` that its first row continues and along it from the line ``start`` where
        it goes, where they have a period) refined at full
        resolution, then one of those within the tolerance of the best, at random. Matched
        with the colours: the local contrast (on the search's grid, ``_coarse``; at full
        resolution, ``_contrast``, where the search is there)."""
        ph, pw = mask.shape
        f = self.f
        if f > 1:
            ssd = self.search.ssd(_coarse(template, f), block_means(mask[:, :, None], f)[
                :, :, 0])
        else:
            template = np.concatenate(
                [template, self.contrast[at[:, :, 0], at[:, :, 1], None]], axis=2)
            ssd = self.search.ssd(template, mask)
        excluded = self._excluded(ssd.shape, ph, pw, used)
        if excluded.all():
            excluded[:] = False
        phase = excluded | self._out_of_phase(np.arange(ssd.shape[0]) * f,
                                              np.arange(ssd.shape[1]) * f, origin, start, frame)
        if not phase.all():
            excluded = phase
        ssd[excluded] = np.inf
        h, w = self.image.shape[:2]
        found, prepared = [], None
        for _ in range(CANDIDATES):
            y, x = np.unravel_index(ssd.argmin(), ssd.shape)
            if not np.isfinite(ssd[y, x]):
                break
            ssd[max(0, y - ph // (4 * f)):y + ph // (4 * f) + 1,
                max(0, x - pw // (4 * f)):x + pw // (4 * f) + 1] = np.inf
            # The same window size for every candidate: the template's spectra are reused.
            y0 = max(0, min(y * f - f, h - ph - 2 * f))
            x0 = max(0, min(x * f - f, w - pw - 2 * f))
            rows, cols = slice(y0, y0 + ph + 2 * f), slice(x0, x0 + pw + 2 * f)
            fine = Search(self.image[rows, cols] if self.own is None else
                          np.concatenate([self.image[rows, cols], self.own[rows, cols]], axis=2))
            prepared = prepared or fine.prepare(template, mask)
            errors = fine.ssd(template, mask, prepared)
            if self.bond is not None:  # a regular lattice: the placement in phase to a pixel
                off = self._out_of_phase(y0 + np.arange(errors.shape[0]),
                                         x0 + np.arange(errors.shape[1]), origin, start, frame,
                                         FINE_PHASE)
                if not off.all():
                    errors[off] = np.inf
            dy, dx = np.unravel_index(errors.argmin(), errors.shape)
            found.append((errors[dy, dx], y0 + int(dy), x0 + int(dx)))
        errors = np.array([e for e, _, _ in found])
        if self.joints is not None:
            # Joints continued across the cuts (issue 41: a clean joint cut beside a mossy one
            # reads as two lines meeting one, two dead ends): the candidates' joint masks
            # against the template's where it is matched.
            t = self.joints[at[:, :, 0], at[:, :, 1]]
            ours = self.joints.T if self.swap else self.joints
            e = self.e
            errors = errors + self.joint * np.array([
                np.einsum("ij,ij->", mask, np.abs(ours[y + e:y + e + ph, x + e:x + e + pw] - t))
                for _, y, x in found])
        near = np.flatnonzero(errors <= errors.min() * (1 + TOLERANCE))
        _, y, x = found[near[rng.integers(len(near))]]
        return y, x

    def patch(self, y, x, ph, pw) -> tuple[np.ndarray, np.ndarray]:
        """The (ph, pw) patch at (y, x) and its photo positions (row, col), int32."""
        i, j = np.meshgrid(np.arange(y, y + ph, dtype=np.int32) + self.e,
                           np.arange(x, x + pw, dtype=np.int32) + self.e, indexing="ij")
        where = np.stack([j, i] if self.swap else [i, j], axis=2)
        return self.image[y:y + ph, x:x + pw], where

    def window(self, y, x, ph, pw) -> tuple[int, int, int, int]:
        """The patch's window in photo coordinates (row, col, rows, cols)."""
        y, x = y + self.e, x + self.e
        return (x, y, pw, ph) if self.swap else (y, x, ph, pw)


def _along(period: int | None, h: int) -> int | None:
    """The courses' period along the vertical arm: the rows' ``period``, where the photo's
    ``h`` rows are a whole number of periods (within ``PHASE``) so that the courses run on
    in phase across the wrap; else None (the horizontal arm's middle cut then absorbs a
    part of a course at the crossing, which no patch in phase with the photo continues)."""
    if period is None or min(h % period, period - h % period) > PHASE * period:
        return None
    return period


def _bond(photo: np.ndarray, period: int | None) -> tuple[int, int] | None:
    """``rhythm.bond`` of ``photo`` with its courses' ``period``, in photo pixels; ``None``
    where the photo's height is no lattice step (its caller: where it is whole courses), or
    its shorter side is ``2 RHYTHM_SIDE`` or more (a deviation: read on a sample, the bond
    would be k pixels coarse, copies n courses away off by n k / 2, and reading it whole took
    2 s at 2048 x 2048)."""
    if period is None or min(photo.shape[:2]) >= 2 * RHYTHM_SIDE:
        return None
    found = rhythm.bond(photo, period)
    if found is None:
        return None
    q, s = found
    # Only where the wrap is a lattice step (its n courses shift the head joints n s, a whole
    # number of Q within PHASE): else the courses beside the wrap are out of bond (the pavers'
    # centre 640, 5 courses: the head joints either side 143 px apart, where a middle cut
    # absorbs what no patch a lattice step away continues; dead-end ratio 1.13-1.37 with the
    # bond, 1.11-1.25 without).
    r = round(photo.shape[0] / period) * s % q
    return (q, s) if min(r, q - r) <= PHASE * q else None


def _contrast(image: np.ndarray) -> np.ndarray:
    """The local contrast of ``image`` (h, w, C), float32 (h, w): the root of ``CONTRAST`` x
    the variance within ``CONTRAST_BOX`` x ``CONTRAST_BOX`` pixels, its channels' summed."""
    a = np.asarray(image, np.float32)
    size = (CONTRAST_BOX, CONTRAST_BOX)
    v = ndimage.uniform_filter(np.einsum("ijc,ijc->ij", a, a), size, mode="nearest")
    for k in range(a.shape[2]):
        v -= ndimage.uniform_filter(a[:, :, k], size, mode="nearest") ** 2
    return np.sqrt(np.float32(CONTRAST) * np.maximum(v, 0))


def _coarse(image: np.ndarray, f: int) -> np.ndarray:
    """``image``'s ``f`` x ``f`` block means and their contrast as one more channel: the root
    of ``CONTRAST`` x the variance within each block, its channels' summed, over ``f^2`` (the
    variance of a block mean of ``f^2`` independent pixels), float64."""
    mean = block_means(image, f)
    square = block_means(np.einsum("ijc,ijc->ij", image, image)[:, :, None], f)[:, :, 0]
    v = np.maximum(square - np.einsum("ijc,ijc->ij", mean, mean), 0)
    return np.concatenate([mean, np.sqrt(CONTRAST * v / (f * f))[:, :, None]], axis=2)


def _unlike(photo: np.ndarray, rows: np.ndarray, b: int, channels: bool = False) -> np.ndarray:
    """Which of the ``rows`` of ``photo`` (h, w, C) have a mean colour like none of the inner
    rows' (those farther than ``b`` from the edges): bool (len(rows),); with ``channels``, in
    each channel by itself, (len(rows), C). An edge's ledge or shadow is unlike them; a course
    of joints recurs inside and is not."""
    mean = photo.mean(axis=1, dtype=np.float32)
    inner = mean[b:len(photo) - b]
    if len(inner) < MIN_INNER:
        return np.zeros((len(rows), photo.shape[2]) if channels else len(rows), bool)
    sigma = 1.4826 * np.median(np.abs(inner - np.median(inner, axis=0)), axis=0)
    # Unlike every inner row: for each, farther than UNLIKE sigma in some channel.
    far = np.abs(mean[rows][:, None] - inner[None]) > UNLIKE * sigma
    return far.all(axis=1) if channels else far.any(axis=2).all(axis=1)


def _layer(current, current_at, lo, hi, matched, counted, source, lay, rng, report, used,
           origin, frame=None):
    """One row of patches quilted along the arm over rows ``lo .. hi - 1`` of ``current``
    (side, length, C): each patch matched to ``current`` on the rows ``matched`` and to its
    neighbours in the overlaps, cut against them (the error counted on the rows ``counted``);
    in phase with the courses from the photo line ``origin`` (row ``lo``'s, as continued).
    Returns the layer (hi - lo, length, C) and its positions."""
    length = current.shape[1]
    strip, at = current[lo:hi].copy(), current_at[lo:hi].copy()
    ph = hi - lo
    starts = lay.starts(length)
    n, ov = len(starts) - 1, lay.overlap
    # The ring closes halfway along the arm (the last patch quilted is fitted to neighbours on
    # both sides); the crossing is passed by consecutive patches. The horizontal arm is quilted
    # from its last patch to its first (right to left), the vertical from first to last.
    order = range(n) if source.swap else range(n - 1, -1, -1)
    placed = np.zeros(n, bool)
    for i, k in enumerate(order):
        before, after = placed[k - 1], placed[(k + 1) % n]
        pw = starts[k + 1] - starts[k] + ov
        cols = (starts[k] + np.arange(pw)) % length
        template = strip[:, cols]
        mask = np.repeat(matched[:, None], pw, axis=1).astype(np.float32)
        if before:
            mask[:, :ov] = 1
        if after:
            mask[:, -ov:] = 1
        y, x = source.choose(template, at[:, cols], mask, rng, used, origin,
                             int(starts[k] % length), frame)
        used.append(source.window(y, x, ph, pw))
        patch, where = source.patch(y, x, ph, pw)
        # Efros & Freeman 2.1: the cuts through the overlaps with the neighbours.
        e = np.einsum("ijc,ijc->ij", patch - template, patch - template) * counted[:, None]
        new = np.ones((ph, pw), bool)
        if before:
            new[:, :ov] = np.arange(ov) >= min_error_path(
                _beside(e[:, :ov], patch[:, :ov], template[:, :ov], source))[:, None]
        if after:
            new[:, pw - ov:] &= np.arange(ov) <= min_error_path(
                _beside(e[:, pw - ov:], patch[:, pw - ov:], template[:, pw - ov:], source))[
                    :, None]
        strip[:, cols] = np.where(new[:, :, None], patch, template)
        at[:, cols] = np.where(new[:, :, None], where, at[:, cols])
        placed[k] = True
        report((i + 1) / n, "Make tileable: quilting")
    return strip, at


def _across(piece: np.ndarray) -> np.ndarray:
    """Which pixels of an overlap ``piece`` (rows, k, C) lie on a line across the arm (a head
    joint between two elements of a course): bool (rows, k), the luma farther than ``LINE``
    robust standard deviations (1.4826 x the median absolute deviation) from its row's
    median; a course's own pixels and a bed joint along the whole row are not."""
    y = luma(piece)
    median = np.median(y, axis=1, keepdims=True)
    spread = 1.4826 * np.median(np.abs(y - median), axis=1, keepdims=True)
    return np.abs(y - median) > LINE * np.maximum(spread, np.float32(1e-6))


def _runs(line: np.ndarray, k: int) -> np.ndarray:
    """The pixels of ``line`` (rows, length) in runs of at least ``k`` across the arm (down its
    rows): a head joint crosses the overlap, the grain's odd pixels do not."""
    return ndimage.binary_opening(line, np.ones((max(1, k), 1), bool))


def _beside(e, patch, template, source) -> np.ndarray:
    """The error surface of a cut between neighbouring patches through their overlap: ``e``,
    and where the photo has courses across the arm (``source.period``), the pixels on a line
    across it in either (:func:`_across`) barred where the cut can go beside them."""
    if source.period is None:
        return e
    barred = _across(patch) | _across(template)
    return e + barred * (e.sum() + 1.0)


def _cut(a, b, lo, hi, barred=None):
    """The closed minimum error cut between arm contents ``a`` and ``b`` through rows
    ``lo .. hi - 1``: its row at each position along the arm. ``barred`` (hi - lo,) or
    (hi - lo, length): rows (pixels) the cut may not pass where it can go elsewhere."""
    e = np.einsum("ijc,ijc->ij", a[lo:hi] - b[lo:hi], a[lo:hi] - b[lo:hi])
    if barred is not None and barred.any():
        e[barred] = e.sum() + 1.0
    return lo + min_error_path(e.T, closed=True)


#: Where the progress is when the first arm starts, the second, the correction, and when it
#: ends (issue 40: wall times in fresh processes, 1024^2 to 2560^2: the set-up before the first
#: arm 0.06-0.14 of the whole, the second arm from 0.38-0.49, the correction from 0.65-0.85;
#: 0.02, 0.45 and 0.85 had read 1.2-2.2 at 10 % on 1536^2 and 0.4-0.6 at 90 %).
STAGES = (0.08, 0.41, 0.76, 0.99)
#: The progress at the end of an arm's first and second rows of patches; the cuts take the
#: rest (measured at 768 x 768, default band: 0.16 and 0.18 of an arm's time; at 0.05 the
#: time left read 2.5-3x at 90 %).
LAYERS = (0.45, 0.85)


def _arm(kept, kept_at, unlike, source, lay, rng, report, used):
    """One arm quilted: ``kept`` (side, length, C) is the photo across the arm (the seam
    between rows ``m + top - 1`` and ``m + top``, the band rows ``m .. m + b - 1``),
    ``kept_at`` its positions, ``unlike`` (side,) its rows left unmatched (:func:`_unlike`).
    Two rows of patches: the first continues the photo before the seam past it, the second
    the photo after the seam back over the first; they meet along a cut in the middle of the
    band (before the seam where the courses across the arm jump at the wrap), and the photo
    along a cut on either side. Returns the arm and its positions."""
    side = len(kept)
    seam, d, c = lay.m + lay.top, lay.d, lay.c
    inner, outer = lay.m + c, lay.m + lay.b - c
    rows = np.arange(side)
    # Only the band's own rows are left unmatched: the kept rows beyond it stay beside it.
    unlike = unlike & (rows >= lay.m) & (rows < lay.m + lay.b)
    first, first_at = _layer(kept, kept_at, 0, seam + d,
                             (rows < inner)[:seam + d] & ~unlike[:seam + d],
                             rows[:seam + d] >= lay.m, source, lay, rng,
                             report.span(0, LAYERS[0]), used, source.across - seam)
    current, current_at = kept.copy(), kept_at.copy()
    current[:seam + d], current_at[:seam + d] = first, first_at
    below = rows[seam - d:]
    second, second_at = _layer(current, current_at, seam - d, side,
                               (below < seam + d) | ((below >= outer) & ~unlike[seam - d:]),
                               below < lay.m + lay.b,
                               source, lay, rng, report.span(*LAYERS), used, -d,
                               source.across - d if source.swap else None)
    current[seam - d:], current_at[seam - d:] = second, second_at
    # The cuts with the photo keep none of its unlike rows: the photo is kept on the rows before
    # the top cut (after the bottom one), so the cut may not pass below (above) one of them.
    count = np.concatenate([[0], np.cumsum(unlike)])  # unlike rows before each row
    end = lay.m + lay.b
    top = _cut(first, kept, lay.m, inner, count[lay.m:inner] > count[lay.m])
    # Courses whose phase jumps at the wrap (:func:`_along`: the photo's height no whole number
    # of periods): the middle cut stays before the seam, the wrap line all in the second row.
    jumps = source.period is not None and _along(source.period, source.across) is None
    low, high = seam - d, seam if jumps else seam + d
    # Where the courses run on in phase across the wrap, the middle cut passes beside their
    # head joints (the two rows may hold them apart: the wrap is a lattice step within PHASE).
    middle = _cut(first, current, low, high, None if source.period is None or jumps else
                  _runs(_across(first[low:high]) | _across(current[low:high]), d // 2))
    bottom = _cut(current, kept, outer, end, count[outer + 1:end + 1] < count[end])
    r = rows[:, None]
    out = np.where(((r < top) | (r > bottom))[:, :, None], kept, current)
    out_at = np.where(((r < top) | (r > bottom))[:, :, None], kept_at, current_at)
    upper = ((r >= top) & (r < middle))[:seam + d, :, None]
    out[:seam + d] = np.where(upper, first, out[:seam + d])
    out_at[:seam + d] = np.where(upper, first_at, out_at[:seam + d])
    report(1.0, "Make tileable: cuts")
    return out, out_at


#: A photo that already tiles: the check's and the copy's reference seconds a pixel, beside
#: their pages (:func:`budget.seconds`), fitted at 4 MP, where the time first counts (the
#: photos section's 2048 setts: 0.24-0.30 s in fresh processes at machine factor 0.25, told
#: 0.17-0.20 s at 1.2e-7; 1 MP copies take 0.025 s, told 0.06 s, under any budget's notice),
#: and the bytes a pixel beside the copy's float32 channels (the positions, int32 x 2, and the
#: check's luminance and sums; 27 measured at 1 and 4 MP).
TILED_SECONDS_PER_PIXEL, TILED_BYTES_PER_PIXEL = 1.6e-7, 16


def predict(shape, band: int | None = None, photo=None) -> tuple[float, float]:
    """(seconds on this machine, peak bytes) predicted for :func:`make_tileable` of a photo of
    ``shape`` (H, W[, C]) with ``band`` (default :func:`default_band`): what the budgets check
    and the Blender panel shows. Given the ``photo`` itself, one that already tiles
    (:func:`tiles`) is predicted as what it costs: the check and a copy.

    Examples
    --------
    >>> seconds, peak = predict((1024, 1024, 3))
    >>> peak < 2**30
    True
    >>> noise = np.random.default_rng(0).random((256, 256, 3))  # tiles: the check, a copy
    >>> predict(noise.shape, photo=noise)[0] < predict(noise.shape)[0]
    True
    """
    h, w = shape[:2]
    c = shape[2] if len(shape) == 3 else 1
    if photo is not None and tiles(np.asarray(photo)):
        peak = float(h * w * (4 * c + TILED_BYTES_PER_PIXEL))
        return budget.seconds(TILED_SECONDS_PER_PIXEL * h * w, peak), peak
    lay = _Layout(h, w, default_band((h, w)) if band is None else band)
    peak = _memory(lay, c)
    return budget.seconds(_cost(lay, c), peak), peak


def _work(lay: _Layout) -> tuple[float, float]:
    """The elements the patches' searches transform (per channel plus two: the mask and the
    squares): on the block means, and in the ``CANDIDATES`` refinement windows."""
    f, e = lay.f, lay.e
    patches = refine = 0.0
    for length in (lay.h, lay.w):
        n = len(lay.starts(length)) - 1
        ph, pw = lay.m + lay.top + lay.d, length / n + lay.overlap
        patches += 2 * n
        refine += 2 * n * CANDIDATES * (ph + 2 * f) * (pw + 2 * f)
    return patches * ((lay.h - 2 * e) // f) * ((lay.w - 2 * e) // f), refine


#: The gradient-domain correction's sweeps the models count (4 on every large photo).
SWEEPS = 4


def _cost(lay: _Layout, c: int) -> float:
    """Seconds on the reference machine: the searches' FFTs (:func:`_work`, per channel, the
    contrast's and two more), fitted by
    non-negative least squares on quiet runs of 1024^2 photos with bands of 48, 128 and 256,
    2048^2 and 4000 x 3000 with 150 and 375 (within 0.82-1.27 of each); the cuts' dynamic
    programmes and the photo-sized copies took no measurable share beside them. The
    correction: ``SWEEPS`` x the cross's pixels and their edge rows, per channel, at the
    seconds it took beside the quilting in the same runs (1024^2 and 2048^2 twice, 4000 x 3000
    once, at their default bands, on a loaded machine: 0.20-0.41 of the whole time; the
    coefficient within 0.47-1.18 of each, 0.82-1.18 but for one run). The constant 0.029 ->
    1.15 (issue 45: the 1024^2 photo read 1.39 and 1.49 of the predictions table's median
    seconds over cost on two hosts, the larger ones 0.76-1.26; no first-call cost: three calls
    in one process take the same CPU time; cause not found)."""
    coarse, refine = _work(lay)
    cross = SWEEPS * (lay.b + 2) * (lay.h + lay.w) * c
    return 1.15 + (4.9e-8 * coarse + 9.0e-8 * refine) * (c + 3) + 1.6e-7 * cross


def _memory(lay: _Layout, c: int) -> float:
    """Peak bytes: the result and its positions (the photo's size: float32 channels and two
    int32), the block means (float64) and the search's spectra (complex128, per channel and
    the squares), and the larger of: an arm's strips and positions (about five copies: the
    photo across the arm, the two rows of patches, the result) while quilting, the
    correction's float64 strips (about 7.5 of a strip with its edge rows: the strip, its
    residual and spectrum, the guidance; 7.1-7.3 measured at 1024^2-4000 x 3000) after it.
    A photo given as bytes adds its float32 copy."""
    h, w, side, f, e = lay.h, lay.w, lay.side, lay.f, lay.e
    photo = h * w * (4 * c + 8 + 12)  # and the contrast map (float32, two temporaries)
    arm = 5 * side * max(h, w) * (4 * c + 8)
    correction = 7.5 * (lay.b + 2) * max(h, w) * c * 8
    search = (h // f) * w * c * 8 + ((h - 2 * e) // f) * ((w - 2 * e) // f) * (c + 2) * 16 * 2
    return float(photo + search + max(arm, correction))


@serial_blas()
def make_tileable(photo, *, band: int | None = None, seed: int = 0,
                  progress: Callable[[float, str], object] | None = None) -> np.ndarray:
    """``photo`` made to tile, float32 of the photo's size and channels.

    Parameters
    ----------
    photo : array (H, W) or (H, W, C), C in 1, 3, 4
        Floats as they are, uint8/uint16 scaled to [0, 1] (as ``texsynth.synthesize``).
    band : int, optional
        Width in pixels of the band quilted across the wrap (each arm of the cross); default
        :func:`default_band`. Wider bands hide larger features; at most half of the photo may
        change.
    seed : int
        Same inputs and seed give bit-identical output; other seeds choose other patches.
    progress : callable(fraction, message), optional
        As for ``texsynth.synthesize``; returning ``False`` cancels (``texsynth.Cancelled``).

    Returns
    -------
    numpy.ndarray
        Every pixel farther than ``band / 2`` from the photo's edges unchanged; the band made
        of photo pieces, their level corrected to meet the kept photo without a step. A photo
        that already tiles (:func:`tiles`) comes back as it is.

    References
    ----------
    Efros & Freeman 2001, 2.1; Pérez, Gangnet & Blake 2003, 2-3 (see the module's docstring).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> photo = rng.random((64, 96, 3)).astype(np.float32)
    >>> tile = make_tileable(photo, seed=1)
    >>> tile.shape, bool((tile[24:40, 24:72] == photo[24:40, 24:72]).all())
    ((64, 96, 3), True)
    """
    return make_tileable_positions(photo, band=band, seed=seed, progress=progress)[0]


def check(shape, *, band: int | None = None, seed: int = 0) -> tuple[int, int]:
    """Every check :func:`make_tileable` makes before any work, from the photo's shape alone:
    ``(band, seed)`` as it takes them, or ``ValueError`` (``BudgetError`` over a budget).

    Examples
    --------
    >>> check((512, 512, 3))
    (64, 0)
    """
    validation.check_side(shape, MIN_SIDE, "photo")
    seed = validation.seed(seed)
    h, w = shape[:2]
    widest = _widest((h, w))
    if widest < MIN_BAND:  # no band is possible: say so, not "between 8 and 7 pixels"
        raise ValueError(f"photo is {w} x {h} pixels, too small to make tileable: even a band "
                         f"of {MIN_BAND} pixels would change more than half of it; use a larger "
                         "photo (28 x 28 pixels at least)")
    band = default_band((h, w)) if band is None else validation.whole(band, "band (pixels)", 1)
    if not MIN_BAND <= band <= widest:
        raise ValueError(f"band must be between {MIN_BAND} and {widest} pixels (wider would "
                         f"change more than half of the {w} x {h} photo), got {band}")
    what = f"making the {w} x {h} photo tileable"
    seconds, peak = predict((h, w, shape[2] if len(shape) == 3 else 1), band)
    budget.admit(what, peak=peak, seconds=seconds, memory_advice="a narrower band",
                 time_advice="try a smaller photo or a narrower band")
    return band, seed


@serial_blas()
def make_tileable_positions(photo, *, band: int | None = None, seed: int = 0,
                            progress: Callable[[float, str], object] | None = None
                            ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`make_tileable` and its position map: where each pixel's piece came from.

    ``follow(positions, other_map, band=band)`` makes another map of the material tile the
    same way; ``texsynth.apply_positions`` gives the pieces before the band's correction.

    Parameters
    ----------
    photo : array (H, W) or (H, W, C), C in 1, 3, 4
        As for :func:`make_tileable`.
    band : int, optional
        Width in pixels of the band quilted across the wrap; default :func:`default_band`.
    seed : int
        Same inputs and seed give bit-identical output.
    progress : callable(fraction, message), optional
        As for ``texsynth.synthesize``; returning ``False`` cancels (``texsynth.Cancelled``).

    Returns
    -------
    tile : numpy.ndarray
        What :func:`make_tileable` returns.
    positions : numpy.ndarray
        int32 (H, W, 2), (row, col) into the photo (the kept pixels map to themselves).

    References
    ----------
    Efros & Freeman 2001, 2.1 (the pieces and their cuts); Pérez, Gangnet & Blake 2003, 2-3
    (the band's level correction, which ``follow`` repeats on the other map).

    Examples
    --------
    >>> photo = np.random.default_rng(0).random((48, 48, 3)).astype(np.float32)
    >>> tile, positions = make_tileable_positions(photo)  # a band of 16: 8 pixels in from the edges
    >>> bool((follow(positions, photo) == tile).all()), bool((tile[8:40, 8:40] == photo[
    ...     8:40, 8:40]).all())
    (True, True)
    """
    a = validation.image(photo, what="photo", min_side=1)
    band, seed = check(a.shape, band=band, seed=seed)
    h, w, c = a.shape
    # Values of huge or tiny magnitude are quilted at an exact power-of-two scale (squared
    # differences near 1e30 overflow float32), and the result is the photo's own pixels.
    scale = validation.magnitude_scale(a)
    given, a = a, validation.ordinary(a, scale)
    rng, report = budget.start(seed, progress)
    if tiles(a):  # the photo already tiles: returned as it is, every pixel its own position
        report(1.0, "Make tileable: the photo already tiles")
        return given.copy(), np.moveaxis(np.indices((h, w), np.int32), 0, 2).copy()
    report(0.0, "Make tileable: starting")

    lay = _Layout(h, w, band)
    out = a.copy()
    positions = np.moveaxis(np.indices((h, w), np.int32), 0, 2).copy()
    e = lay.e
    inside = a[e:h - e, e:w - e]
    coarse = _coarse(inside, lay.f) if lay.f > 1 else None
    contrast = _contrast(a) if lay.f == 1 else None
    used: list[tuple[int, int, int, int]] = []
    # The seam between the last and first rows (columns) is row m + top of the arm's strip;
    # the band is rows m .. m + b - 1.
    band_rows = slice(lay.m, lay.m + band)
    rows = (np.arange(lay.side) - lay.top - lay.m) % h
    period = rhythm.course_period(a[:, ::max(1, w // RHYTHM_SIDE)])
    bond = _bond(a, period) if _along(period, h) is not None else None
    joints, joint = None, 0.0
    if bond is not None:
        joints = joint_mask(a, JOINT_SIGMA).astype(np.float32)
        joint = JOINT * float(a.reshape(-1, c).var(axis=0).sum())
    across = _Source(inside, contrast, coarse, lay.f, e, swap=False, period=period, bond=bond,
                     joints=joints, joint=joint)
    strip, at = _arm(a[rows], positions[rows], _unlike(a, rows, band), across, lay, rng,
                     report.span(*STAGES[0:2]), used)
    out[rows[band_rows]] = strip[band_rows]
    positions[rows[band_rows]] = at[band_rows]

    cols = (np.arange(lay.side) - lay.top - lay.m) % w
    down = _Source(inside.transpose(1, 0, 2), contrast,
                   None if coarse is None else coarse.transpose(1, 0, 2), lay.f, e, swap=True,
                   along=_along(across.period, h), bond=bond, joints=joints, joint=joint)
    strip, at = _arm(out[:, cols].transpose(1, 0, 2), positions[:, cols].transpose(1, 0, 2),
                     _unlike(a.transpose(1, 0, 2), cols, band), down, lay, rng,
                     report.span(*STAGES[1:3]), used)
    out[:, cols[band_rows]] = strip[band_rows].transpose(1, 0, 2)
    positions[:, cols[band_rows]] = at[band_rows].transpose(1, 0, 2)
    out = _correct(out, given, a, scale, positions, band, report.span(*STAGES[2:4]))
    report(1.0, "Make tileable: done")
    return out, positions


def follow(positions, image, *, band: int | None = None) -> np.ndarray:
    """Another map of the photo's material (normal, roughness, height... of the photo's size)
    made to tile the way :func:`make_tileable_positions` made the photo: its pixels moved by
    ``positions``, then the band corrected from the map's own gradients (Pérez et al. 2003, as
    the photo's); identity positions (the photo already tiled) leave the map as it is.
    ``band`` must be the one the photo was made with (default :func:`default_band`). Given the
    photo itself, it gives back the photo's result bit for bit.

    Returns
    -------
    numpy.ndarray
        float32 (H, W, C), ``image``'s size and channels (uint8/uint16 scaled to [0, 1]).

    References
    ----------
    Pérez, Gangnet & Blake 2003, 2-3 (``texsynth.blocks.poisson``).

    Examples
    --------
    >>> photo = np.random.default_rng(0).random((48, 48, 3)).astype(np.float32)
    >>> tile, positions = make_tileable_positions(photo)
    >>> bool((follow(positions, photo) == tile).all())
    True
    """
    given = validation.image(image, what="image", min_side=MIN_SIDE, channels=None)
    p = np.asarray(positions)
    if p.shape != given.shape[:2] + (2,) or p.dtype.kind not in "iu":
        raise ValueError(f"positions must be an integer array of the image's size "
                         f"({given.shape[0]}, {given.shape[1]}, 2), got {p.dtype} {p.shape}")
    if p.min() < 0 or (p.reshape(-1, 2).max(axis=0) >= given.shape[:2]).any():
        raise ValueError("positions point outside the image: give the map of the photo's size "
                         "that the positions were made for")
    band = default_band(given.shape) if band is None else validation.whole(
        band, "band (pixels)", 1)
    if not MIN_BAND <= band <= _widest(given.shape):
        raise ValueError(f"band must be between {MIN_BAND} and {_widest(given.shape)} pixels, "
                         f"the band the photo was made with, got {band}")
    if (p == np.moveaxis(np.indices(p.shape[:2]), 0, 2)).all():  # a photo that already tiled
        return given.copy()
    scale = validation.magnitude_scale(given)
    a = given if scale == 1.0 else (given.astype(np.float64) * scale).astype(np.float32)
    return _correct(a[p[:, :, 0], p[:, :, 1]], given, a, scale, p, band)


def _cross(shape, band: int) -> tuple[np.ndarray, np.ndarray]:
    """The rows and the columns of the band's two arms (the cross across the wrap)."""
    h, w = shape[:2]
    return (np.arange(band) - band // 2) % h, (np.arange(band) - band // 2) % w


#: The correction's progress before its first solve: the guidance (the pieces' gradients)
#: and the kept steps (measured at 768 x 768, default band: 0.6 of the correction's time).
GUIDANCE = 0.6
#: The sweeps the correction's progress counts on (issue 40): the median of 13 photos of
#: shared/textures at 512^2-1024^2 (3 in 9, 4 in 3, 5 in 1; the cost's ``SWEEPS`` is the
#: large photos'); with 4, the 768 brick's 3 had left the last quarter of the correction's
#: share to no work, told 1.59x at 90 %.
TOLD_SWEEPS = 3


def _correct(out, given, a, scale, positions, band, report=None) -> np.ndarray:
    """The quilt ``out`` of ``a`` (``given`` times the power of two ``scale``) with its cross
    replaced by Pérez et al. 2003's guided interpolation (``texsynth.blocks.poisson``), guided
    by the gradients of the pieces of ``a`` at ``positions``, clipped to ``a``'s range in each
    channel (the correction makes no value the photo does not have), and brought back to
    ``given``'s magnitude: outside the cross, ``given``'s own pixels. ``report``: a
    ``Progress`` span, told after each strip's solve."""
    lo, hi = a.min(axis=(0, 1)), a.max(axis=(0, 1))
    h, w = a.shape[:2]
    # The lines just beyond the band: where one is unlike the photo (a ledge, a shadow along
    # an edge), the band keeps its step to it rather than fade into it.
    before, after = -1 - band // 2, band - band // 2
    # Channel by channel, so that a map follows as its channels would alone (:func:`follow`).
    kept_steps = (_unlike(a, np.array([before % h, after % h]), band, channels=True),
                  _unlike(a.transpose(1, 0, 2), np.array([before % w, after % w]), band,
                          channels=True))
    tick = None if report is None else (
        lambda done: report(GUIDANCE + (1.0 - GUIDANCE) * min(1.0, done / (2 * TOLD_SWEEPS)),
                            "Make tileable: level of the band"))
    poisson.correct_cross(out, a, positions, band, float((hi - lo).max()), kept_steps, tick)
    rows, cols = _cross(out.shape, band)
    out[rows] = np.clip(out[rows], lo, hi)
    out[:, cols] = np.clip(out[:, cols], lo, hi)
    if scale == 1.0:
        return out
    result = given.copy()
    # Dividing by a power of two is exact (in float64, where 2^-k may be below float32's range).
    result[rows] = (out[rows].astype(np.float64) / scale).astype(np.float32)
    result[:, cols] = (out[:, cols].astype(np.float64) / scale).astype(np.float32)
    return result
