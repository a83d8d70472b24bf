"""Line evidence: straight segments of a photo, their families, and what they say of the plane.

Segments follow Burns, Hanson & Riseman 1986 ("Extracting straight lines"): strong pixels are
grouped by direction into connected "line-support regions" (two bin partitions offset by half
a bin, each pixel voting for the longer of its two regions), and each region's weighted
principal axis is the segment. Deviation: the pixels are the centre lines of dark and bright
lines, not of step edges: a joint in a photo (mortar, the gap between setts or pavers) is a
line a few pixels wide, irregular and shaded, often standing out in colour more than in
luminance, and Lindeberg's (1998) scale-normalised ridge strength over a few scales and over
luminance and two chroma channels finds it where the two weak edges of its sides did not.
Families are vanishing points found by RANSAC on the Gauss sphere (Barnard 1983; the
consistency test of Rother 2002: the angle between a segment and the line from its midpoint
to the vanishing point), refined by least squares; segments weigh by length and contrast.
Within each of two families, collinear segments are then joined across their gaps into one line
(:func:`_joined`): a joint broken by every brick is one long, precise line.

On a plane the families' directions are parallel, and (bricks, tiles, planks, weaves) the two
main families are orthogonal. For a plane hypothesis, :class:`LineCost` back-projects every
segment direction by the local Jacobian of :func:`~texsynth.plane.geometry.jacobians` and scores
how far each family is from parallel and the two families from orthogonal, in units of each
segment's own direction noise: parallelism fixes the vanishing line v, orthogonality one more
constraint, so two families give slant, tilt and the focal length in closed form (Caprile &
Torre 1990: f^2 = -x1 . x2 for orthogonal vanishing points x1, x2) and one family one constraint.

One family alone (boards without visible butt joints): its vanishing point puts the horizon
through a point (:func:`horizon_through`); the lines' equal spacing on the plane gives the rest
(:func:`spaced_horizon`: homogeneity, sec. 11.4.1 of Forsyth & Ponce, applied to the lines'
positions instead of filter energies; a Rayleigh test of periodicity replaces texel counts).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import scipy.ndimage as ndi
from scipy import sparse
from scipy.sparse import csgraph

from .. import validation
from .geometry import jacobians
from .spectra import block_mean, downsample

__all__ = ["Segments", "segments", "fine_segments", "photo_families", "families", "vanishing_point",
           "horizon_through", "spaced_horizon", "distinct_lines", "LineCost"]

_BINS = 16            # gradient direction bins over [0, 2 pi): 22.5 degrees, polarity kept
_LINE_BINS = 8        # line direction bins over [0, pi): 22.5 degrees (dark and bright alike)
_SCALES = (1.0, 1.5, 2.5)  # ridge filter scales (pixels): joints about 2 to 8 pixels wide
_MIN_LENGTH = 10.0    # shortest segment kept (analysis pixels)
_MAX_WIDTH = 0.25     # widest support region kept, as a share of its length
_STRONG = 3.0         # gradient magnitude threshold, in units of its median over textured pixels
_DENSE = 1.5          # ... where _STRONG leaves too few segments (dense patterns: weaves)
_CONTRAST_CAP = 12.0  # strongest contrast a segment's weight counts (units of the median)
_RANSAC = 400         # hypotheses per vanishing point
_INLIER_DEG = 1.5     # consistency threshold (degrees), plus the direction noise of short segments
_DISTINCT_DEG = 30.0  # least image angle of the second family to the first's vanishing point
_MIN_FAMILY = 6       # segments a family needs
_MIN_SUPPORT = 0.75   # total length of a family, in image sides
_OVER_CHANCE = 3.0    # ... and this many times what random directions would give
ORTHOGONAL_DEG = 1.0  # how far (one sigma) the texture's two families may be from orthogonal
_G_SPACED = 0.05     # depth ratio segments must keep under a horizon hypothesis
_CYCLES = np.arange(3.0, 60.0, 0.05)  # periods across the family tested for equal spacing
_CENTRAL = (10.0, 90.0)  # percentiles of the offsets across which the periods are counted
_SPACED_Z = 12.0     # Rayleigh statistic an equal spacing needs (measured on the plane renders:
#                      wrong lone families reach 9.7, right ones and the test boards 12.9 up)
_SPACED_DROP = 2.0   # log-likelihood units below the best periodicity a horizon is not ruled out
#                      at (two sigmas of a one-parameter profile likelihood)
_ROBUST = 3.0         # standardised residual beyond which the loss turns logarithmic
_JOIN_PX = 1.5       # how far (fine pixels) a segment may lie off another's line to be joined to it
_JOIN_ROWS = 256     # segments compared with all others at a time when joining
_SAME_LINE = 3.0     # pixels: segments whose lines through the vanishing point pass this close
#                      to each other at the image centre are one line (a joint's two sides, its
#                      broken pieces)
_SPACED_LINES = 5    # distinct lines an equal spacing needs: three are equally spaced under some
#                      horizon whatever their offsets (two gaps, one free position of the
#                      horizon), and the period and its phase take two more
_LINE_SIDE = 640      # segments are found at up to this longer side (joints are 1-3 px wide
#                       at the texture's analysis size, head joints under _MIN_LENGTH long)
RIDGE_SIDE = 1024     # ... their centre lines at up to this side (a brick wall's head joints, 20-30
#                       px long there, fell under _MIN_LENGTH at 640)


@dataclass(frozen=True)
class Segments:
    """Straight segments: midpoints ``m`` (N, 2), unit directions ``d`` (N, 2) and lengths (N,),
    in centred y-up pixels of the analysed image (:mod:`texsynth.plane.geometry`); ``dense``:
    found at the lower threshold of a dense pattern (:func:`segments`); ``pixel``: the side of
    the pixels they were found in, in those units (:func:`fine_segments`: under 1)."""

    m: np.ndarray
    d: np.ndarray
    length: np.ndarray
    dense: bool = False
    pixel: float = 1.0
    contrast: np.ndarray | None = None

    @property
    def weight(self) -> np.ndarray:
        """Weight in the vanishing-point fits: length times contrast (the mean strength over
        its median across the image, at most ``_CONTRAST_CAP``): a faint run of grain near the
        threshold counts for less than a joint of the same length, and one very strong edge
        (a shadow, the wall's end) for no more than a few joints."""
        if self.contrast is None:
            return self.length
        return self.length * np.minimum(self.contrast, _CONTRAST_CAP)

    def __len__(self) -> int:
        return len(self.length)

    def take(self, keep) -> Segments:
        return Segments(self.m[keep], self.d[keep], self.length[keep], self.dense, self.pixel,
                        None if self.contrast is None else self.contrast[keep])

    @property
    def noise(self) -> np.ndarray:
        """One-sigma direction noise (radians): a pixel's worth across each segment."""
        return _noise(self.length / self.pixel)


def segments(lum: np.ndarray, mask: np.ndarray, chroma=None) -> Segments:
    """Straight segments of ``lum`` (textured pixels ``mask`` only): Burns et al.'s step edges,
    or with ``chroma`` (a list of chroma channels, possibly empty) the centre lines of dark
    and bright lines in luminance and chroma (:func:`_ridges`).

    Pixels are strong above ``_STRONG`` times the median response; where that leaves fewer
    segments than two families need, above ``_DENSE`` times it (a dense pattern: in a weave
    every pixel lies on a thread's edge, so the median is itself high and the cell edges stand
    only about twice above it). Such segments are thread edges in short bundles, equally spaced
    within a cell only: their spacing says nothing of the plane (``dense``)."""
    found = _EMPTY
    for level, dense in ((_STRONG, False), (_DENSE, True)):
        if chroma is None:
            found = _edge_segments(lum, mask, level)
        else:
            found = _ridge_segments([np.asarray(lum, np.float32), *chroma], mask, level)
        found = replace(found, dense=dense)
        if len(found) >= 2 * _MIN_FAMILY:
            break
    return found


def photo_families(lum: np.ndarray, small: np.ndarray, k: int, mask: np.ndarray,
                   image=None) -> list[Segments]:
    """The line families (:func:`families`) of a photo (luminance ``lum``, colour ``image``;
    analysed as ``small``, ``lum`` block-averaged by ``k``, textured where ``mask``): those of
    its step edges, or of its lines' centres (:func:`fine_segments` with ``ridges``) where
    these give more families. Step edges are the more precise on clean, high-contrast joints,
    and a board's grain (itself a bundle of fine ridges) would hide its seams' spacing; the
    joints of real walls and pavements are lines a few pixels wide, irregular and shaded,
    whose two weak edges leave a family out. Two families come with their collinear segments
    joined (:func:`_joined`); a lone one as found, for its spacing (:func:`spaced_horizon`).

    Parameters
    ----------
    lum, small, k, mask : the photo's luminance, its analysis image, the block size between
        them and the analysis image's textured pixels (:mod:`texsynth.plane.spectra`).
    image : array (H, W, C), optional
        The photo in colour, for the chroma channels.

    Returns
    -------
    list of Segments, up to two, the best supported first.

    References
    ----------
    Burns, Hanson & Riseman 1986, "Extracting straight lines"; Lindeberg 1998, "Edge and ridge
    detection with automatic scale selection", sec. 4.

    Examples
    --------
    >>> import numpy as np
    >>> from texsynth.plane import spectra
    >>> y, x = np.mgrid[0:160, 0:160]
    >>> noise = 0.05 * np.random.default_rng(0).standard_normal((160, 160))
    >>> image = np.where((y % 32 < 3) | (x % 48 < 3), 0.2, 0.6 + noise)  # dark joints
    >>> lum = spectra.luminance(image)
    >>> small, k = spectra.downsample(lum)
    >>> len(photo_families(lum, small, k, spectra.texture_mask(small), image))
    2
    """
    side = float(max(small.shape))
    edges = families(fine_segments(lum, small, k, mask), side)
    if len(edges) < 2:
        centres = families(fine_segments(lum, small, k, mask, image, ridges=True), side)
        edges = centres if len(centres) > len(edges) else edges
    if len(edges) < 2:  # a lone family's spacing test (_SPACED_Z) was calibrated on pieces
        return edges
    return [f if f.dense else _joined(f) for f in edges]


def _joined(family: Segments) -> Segments:
    """The family's collinear segments joined across their gaps into one segment each: a joint
    broken at every brick, every step of its width or every tuft of grass is one straight line,
    and its direction is known to a pixel over its whole length rather than over each piece
    (Burns et al.'s regions end where the gradient direction changes; this is the grouping of
    segments into longer lines of their sec. VI, done within a family). Two segments join when
    each one's midpoint lies within ``_JOIN_PX`` pixels of the other's line and the gap between
    them is at most their summed length; a group is fitted by its weighted second moments (each
    segment a uniform line of its length) and kept joined when it stays that thin."""
    n = len(family)
    if n < 2:
        return family
    m, d, length = family.m, family.d, family.length
    tol = _JOIN_PX * family.pixel
    pairs = []
    for start in range(0, n, _JOIN_ROWS):  # row blocks: memory O(_JOIN_ROWS n), not O(n^2)
        i = np.arange(start, min(start + _JOIN_ROWS, n))
        delta = m[None, :, :] - m[i, None, :]  # m_j - m_i
        across_i = np.abs(d[i, None, 0] * delta[..., 1] - d[i, None, 1] * delta[..., 0])
        across_j = np.abs(d[None, :, 0] * delta[..., 1] - d[None, :, 1] * delta[..., 0])
        reach = length[i, None] + length[None, :]
        gap = np.abs((d[i, None, :] * delta).sum(axis=2)) - 0.5 * reach
        a, b = np.nonzero((across_i <= tol) & (across_j <= tol) & (gap <= reach))
        pairs.append((i[a], b))
    rows, cols = (np.concatenate(x) for x in zip(*pairs, strict=True))
    join = sparse.coo_matrix((np.ones(len(rows), bool), (rows, cols)), shape=(n, n))
    _, group = csgraph.connected_components(join, directed=False)
    weight = length if family.contrast is None else length * family.contrast
    mass = np.bincount(group, weight)
    centre = np.stack([np.bincount(group, weight * m[:, c]) for c in (0, 1)], axis=1)
    centre /= mass[:, None]
    off = m - centre[group]
    second = [np.bincount(group, weight * (length ** 2 / 12.0 * d[:, a] * d[:, b]
                                           + off[:, a] * off[:, b])) / mass
              for a, b in ((0, 0), (0, 1), (1, 1))]
    half = np.hypot((second[0] - second[2]) / 2, second[1])
    major = (second[0] + second[2]) / 2 + half
    minor = np.maximum((second[0] + second[2]) / 2 - half, 0.0)
    theta = 0.5 * np.arctan2(2 * second[1], second[0] - second[2])
    joined_d = np.stack([np.cos(theta), np.sin(theta)], axis=1)
    joined_len = np.sqrt(12.0 * major)
    thin = (np.sqrt(12.0 * minor) <= tol) & (np.bincount(group) > 1)
    single = ~thin[group]
    keep = np.flatnonzero(thin)
    contrast = None if family.contrast is None else np.concatenate(
        [family.contrast[single], (mass / np.bincount(group, length))[keep]])
    return Segments(np.concatenate([m[single], centre[keep]]),
                    np.concatenate([d[single], joined_d[keep]]),
                    np.concatenate([length[single], joined_len[keep]]),
                    family.dense, family.pixel, contrast)


_EMPTY = Segments(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), contrast=np.zeros(0))


def _edge_segments(lum: np.ndarray, mask: np.ndarray, level: float) -> Segments:
    """Burns et al.'s regions of strong gradient, binned by gradient direction (polarity kept)."""
    smooth = ndi.gaussian_filter(lum, 1.0, mode="reflect")
    g_row, g_col = ndi.sobel(smooth, 0), ndi.sobel(smooth, 1)
    magnitude = np.hypot(g_row, g_col)
    textured = mask & (magnitude > 0)
    if not textured.any():
        return _EMPTY
    median = np.median(magnitude[textured])
    angle = np.arctan2(g_row, g_col) % (2 * math.pi) / (2 * math.pi / _BINS)
    found = _support_regions(angle, np.zeros(angle.shape, np.int64), _BINS, magnitude,
                             textured & (magnitude > level * median))
    return replace(found, contrast=None)  # weighed by length alone, as Burns et al.'s


def _ridges(planes, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Line strength (in units of its median over the textured pixels ``mask``) and line
    direction (radians mod pi, from +row towards +col) of every pixel: the strongest over the
    channels ``planes`` and the scales ``_SCALES``.

    The Hessian H of a channel smoothed at scale s: across a line its eigenvalue of larger
    magnitude l1 is large, along it l2 is small; the strength s^2 (|l1| - |l2|) (= s^2
    min(|trace H|, l1 - l2): Lindeberg 1998, "Edge and ridge detection with automatic scale
    selection", sec. 4, normalisation gamma = 1) is 0 on a blob or a flat patch, and a dark line
    (a valley) and a bright one (a ridge) score alike. Deviation: each channel counts in units
    of its own median, so that grey mortar between red bricks of the same luminance, or grass
    between grey setts, stands out in the chroma channel that shows it."""
    best = np.zeros(mask.shape, np.float32)
    hessian = np.zeros((3, *mask.shape), np.float32)  # h_rr - h_cc, 2 h_rc, trace at the best
    for plane in planes:
        strongest = np.zeros(mask.shape, np.float32)
        own = np.zeros_like(hessian)
        for s in _SCALES:
            # Second differences of the smoothed channel: the Gaussian's derivatives at a
            # fraction of the cost (one smoothing per scale).
            g = np.pad(ndi.gaussian_filter(plane, s, mode="reflect", truncate=3.0), 1,
                       mode="reflect")
            centre = g[1:-1, 1:-1]
            h_rr = g[2:, 1:-1] + g[:-2, 1:-1] - 2.0 * centre
            h_cc = g[1:-1, 2:] + g[1:-1, :-2] - 2.0 * centre
            h_rc = 0.25 * (g[2:, 2:] + g[:-2, :-2] - g[2:, :-2] - g[:-2, 2:])
            trace = h_rr + h_cc
            h_rr -= h_cc  # now h_rr - h_cc
            h_rc *= 2.0
            strength = s * s * np.minimum(np.abs(trace), np.hypot(h_rr, h_rc))
            better = strength > strongest
            np.copyto(strongest, strength, where=better)
            for a, b in zip(own, (h_rr, h_rc, trace), strict=True):
                np.copyto(a, b, where=better)
        median = float(np.median(strongest[mask])) if mask.any() else 0.0
        if median <= 0.0:
            continue
        strongest /= median
        better = strongest > best
        np.copyto(best, strongest, where=better)
        for a, b in zip(hessian, own, strict=True):
            np.copyto(a, b, where=better)
    # The eigenvector of the algebraically larger eigenvalue is a dark line's normal; a bright
    # line's normal is the other one, a quarter turn away; the line runs across its normal.
    normal = 0.5 * np.arctan2(hessian[1], hessian[0]) + np.where(hessian[2] < 0, math.pi / 2, 0)
    return best, ((normal + math.pi / 2) % math.pi).astype(np.float32)


def _ridge_segments(planes, mask: np.ndarray, level: float) -> Segments:
    """Centre lines of dark and bright lines (:func:`_ridges`): the pixels above ``level`` that
    are the strongest across their line (non-maximum suppression, Canny 1986), grouped by line
    direction into Burns et al.'s line-support regions. Deviation from Burns et al.: a joint
    (mortar, the gap between setts) is found as one line at its centre, not as two weak edges
    a few pixels apart; direction bins are mod pi, without polarity."""
    strength, direction = _ridges(planes, mask)
    h, w = strength.shape
    across = direction + math.pi / 2  # the neighbours across the line, rounded to the 8 nearest
    step_r = np.round(np.cos(across)).astype(np.intp)
    step_c = np.round(np.sin(across)).astype(np.intp)
    rows, cols = np.nonzero(mask & (strength > level))
    keep = np.ones(len(rows), bool)
    for sign in (1, -1):
        r = np.clip(rows + sign * step_r[rows, cols], 0, h - 1)
        c = np.clip(cols + sign * step_c[rows, cols], 0, w - 1)
        keep &= strength[rows, cols] >= strength[r, c]
    strong = np.zeros((h, w), bool)
    strong[rows[keep], cols[keep]] = True
    return _support_regions(direction / (math.pi / _LINE_BINS), np.zeros((h, w), np.int64),
                            _LINE_BINS, strength, strong)


def fine_segments(lum: np.ndarray, small: np.ndarray, k: int, mask: np.ndarray,
                  image=None, ridges: bool = False) -> Segments:
    """:func:`segments` of the photo's luminance ``lum`` found at up to ``_LINE_SIDE`` pixels
    on its longer side (with ``ridges``: the lines' centres in it and in the chroma of its
    colour ``image``, :func:`_opponent`, at up to ``RIDGE_SIDE``), in the pixels of its analysis
    image ``small`` (``lum`` block-averaged by ``k``, textured where ``mask``). Deviation from
    Burns et al.: the regions are found at the finer size because a real joint (mortar, the
    gap between setts) is 1-3 pixels wide and a head joint shorter than ``_MIN_LENGTH`` at the
    texture's analysis size."""
    fine, k_f = downsample(lum, RIDGE_SIDE if ridges else _LINE_SIDE)
    if k_f >= k:
        fine, k_f = small, k
        fine_mask = mask
    else:
        # The analysis mask at each fine pixel's centre (both images are central crops).
        ratio = k_f / k
        rows, cols = ((np.arange(n) - (n - 1) / 2) * ratio + (m - 1) / 2
                      for n, m in zip(fine.shape, mask.shape, strict=True))
        rows, cols = (np.clip(np.round(x), 0, m - 1).astype(np.intp)
                      for x, m in ((rows, mask.shape[0]), (cols, mask.shape[1])))
        fine_mask = mask[np.ix_(rows, cols)]
    chroma = _opponent(image, k_f) if ridges else None
    found = segments(fine, fine_mask, chroma)
    ratio = k_f / k
    return Segments(found.m * ratio, found.d, found.length * ratio, found.dense,
                    found.pixel * ratio, found.contrast)


def _opponent(image, k: int = 1) -> list[np.ndarray]:
    """The chroma of a colour ``image`` block-averaged by ``k`` (as
    :func:`~texsynth.plane.spectra.downsample`, in float32) as two
    opponent channels, red - green and yellow - blue (none for a grey one): joints that differ
    from the stones in colour more than in luminance."""
    if image is None:
        return []
    a = validation.image(image, what="image", channels=None)
    if a.shape[2] < 3:
        return []
    # Averaging first: the same, cheaper; the three channels in one pass over the photo.
    mean = block_mean(a[:, :, :3], k, np.float32)
    r, g, b = mean[:, :, 0], mean[:, :, 1], mean[:, :, 2]
    return [r - g, 0.5 * (r + g) - b]


def _support_regions(angle, kind, n_bins, magnitude, strong) -> Segments:
    """Burns et al.'s line-support regions of the ``strong`` pixels, fitted by their axes:
    ``angle`` in bin units (``n_bins`` bins wrap around), ``kind`` a further label (polarity)
    that regions do not cross."""
    h, w = magnitude.shape
    rows, cols = np.nonzero(strong)
    weight = magnitude[rows, cols]
    regions = []
    for shift in (0.0, 0.5):
        bins = (np.floor(angle[rows, cols] + shift).astype(np.int64) % n_bins
                + n_bins * kind[rows, cols])
        labels = np.zeros((h, w), np.int64)
        count = 0
        for b in range(n_bins * (int(kind.max(initial=0)) + 1)):
            image = np.zeros((h, w), bool)
            pick = bins == b
            image[rows[pick], cols[pick]] = True
            lab, n = ndi.label(image, structure=np.ones((3, 3)))
            labels[lab > 0] = lab[lab > 0] + count
            count += n
        regions.append(_fit_regions(labels[rows, cols], count, rows, cols, weight))
    # Each pixel votes for the longer of its two regions; a region keeps most of its votes.
    (label_a, fit_a), (label_b, fit_b) = regions
    len_a, len_b = fit_a[2][label_a], fit_b[2][label_b]
    kept = []
    for label, fit, mine in ((label_a, fit_a, len_a >= len_b), (label_b, fit_b, len_b > len_a)):
        votes = np.bincount(label, mine, len(fit[2])) / np.maximum(np.bincount(label,
                                                                               None,
                                                                               len(fit[2])), 1)
        good = (votes > 0.5) & fit[3]
        kept.append((fit[0][good], fit[1][good], fit[2][good], fit[4][good]))
    m = np.concatenate([k[0] for k in kept])
    d = np.concatenate([k[1] for k in kept])
    length = np.concatenate([k[2] for k in kept])
    contrast = np.concatenate([k[3] for k in kept])
    # centred, y up
    m = np.stack([m[:, 1] - (w - 1) / 2, (h - 1) / 2 - m[:, 0]], axis=1)
    d = np.stack([d[:, 1], -d[:, 0]], axis=1)
    return Segments(m, d, length, contrast=contrast)


def _fit_regions(label, count, rows, cols, weight):
    """Per region: midpoint (row, col), unit direction, length, whether it is line-like and
    its mean ``weight`` (strength)."""
    n = count + 1
    label = label.astype(np.int64)
    sums = [np.bincount(label, weight * t, n) for t in
            (np.ones_like(rows, float), rows, cols, rows * rows, rows * cols, cols * cols)]
    pixels = np.bincount(label, None, n)
    s0 = np.maximum(sums[0], 1e-12)
    mr, mc = sums[1] / s0, sums[2] / s0
    crr = sums[3] / s0 - mr * mr
    crc = sums[4] / s0 - mr * mc
    ccc = sums[5] / s0 - mc * mc
    half_diff = np.hypot((crr - ccc) / 2, crc)
    major = (crr + ccc) / 2 + half_diff
    minor = np.maximum((crr + ccc) / 2 - half_diff, 0.0)
    theta = 0.5 * np.arctan2(2 * crc, crr - ccc)  # major axis angle, from +row towards +col
    direction = np.stack([np.cos(theta), np.sin(theta)], axis=1)  # (row, col)
    length = np.sqrt(12.0 * np.maximum(major, 0.0))
    width = np.sqrt(12.0 * minor)
    line_like = (pixels >= 8) & (length >= _MIN_LENGTH) & (width <= _MAX_WIDTH * length)
    line_like[0] = False
    mean = sums[0] / np.maximum(pixels, 1)
    return label, (np.stack([mr, mc], axis=1), direction, length, line_like, mean)


def _noise(length: np.ndarray) -> np.ndarray:
    """One-sigma direction noise (radians) of a segment: a pixel's worth across its length."""
    return np.arctan(1.0 / np.maximum(length, 1.0))


def _consistency(s: Segments, vp: np.ndarray, scale: float) -> np.ndarray:
    """Angles (radians, (K, N)) between segments and the lines from their midpoints to the
    vanishing points ``vp`` (K, 3), homogeneous in pixels / ``scale``."""
    toward = vp[:, None, :2] - vp[:, None, 2:] * (s.m[None] / scale)
    norm = np.maximum(np.linalg.norm(toward, axis=2), 1e-12)
    sine = np.abs(toward[..., 0] * s.d[None, :, 1] - toward[..., 1] * s.d[None, :, 0]) / norm
    return np.arcsin(np.clip(sine, 0.0, 1.0))


def _lines(s: Segments, scale: float) -> np.ndarray:
    """Homogeneous lines (N, 3) through the segments, in pixels / ``scale``."""
    a = np.concatenate([s.m / scale, np.ones((len(s), 1))], axis=1)
    b = np.concatenate([(s.m + s.d) / scale, np.ones((len(s), 1))], axis=1)
    lines = np.cross(a, b)
    return lines / np.linalg.norm(lines[:, :2], axis=1, keepdims=True)


def weighted_lines(family: Segments, side: float) -> np.ndarray:
    """The family's homogeneous lines (N, 3), in pixels / ``side``, each times the square root
    of its segment's weight: the rows whose least singular vector is the weighted
    least-squares vanishing point (:func:`vanishing_point`).

    Examples
    --------
    >>> family = Segments(np.array([[0.0, 10.0], [0.0, -10.0]]), np.array([[1.0, 0.0]] * 2),
    ...                   np.array([4.0, 16.0]))  # two horizontal lines, y = 10 and y = -10
    >>> np.round(weighted_lines(family, 20.0), 3).tolist()  # weights 4 and 16: times 2 and 4
    [[0.0, 2.0, -1.0], [0.0, 4.0, 2.0]]
    """
    return _lines(family, side) * np.sqrt(family.weight)[:, None]


def _vanishing_point(s: Segments, scale: float, rng) -> tuple[np.ndarray, np.ndarray] | None:
    """The best-supported vanishing point (unit 3-vector) and its inliers, or None."""
    if len(s) < _MIN_FAMILY:
        return None
    lines = _lines(s, scale)
    p = s.weight / s.weight.sum()
    i = rng.choice(len(s), _RANSAC, p=p)
    j = rng.choice(len(s), _RANSAC, p=p)
    vp = np.cross(lines[i], lines[j])
    vp = vp[np.linalg.norm(vp, axis=1) > 1e-9]
    if len(vp) == 0:
        return None
    vp /= np.linalg.norm(vp, axis=1, keepdims=True)
    limit = math.radians(_INLIER_DEG) + 2.0 * s.noise
    support = ((_consistency(s, vp, scale) < limit[None]) * s.weight[None]).sum(axis=1)
    best = vp[int(np.argmax(support))]
    for _ in range(3):  # least squares on the inliers: min sum (l . V)^2 L, |V| = 1
        inliers = _consistency(s, best[None], scale)[0] < limit
        if inliers.sum() < 2:
            return None
        weighted = lines[inliers] * np.sqrt(s.weight[inliers])[:, None]
        best = np.linalg.svd(weighted, full_matrices=False)[2][-1]
    inliers = _consistency(s, best[None], scale)[0] < limit
    return best, inliers


def families(s: Segments, side: float, seed: int = 0) -> list[Segments]:
    """Up to two families of segments sharing a vanishing point, the best supported first.

    A family needs ``_MIN_FAMILY`` segments, a total length of ``_MIN_SUPPORT`` image sides
    (``side``: the longer one, pixels) and ``_OVER_CHANCE`` times the length that segments of
    random directions would line up by chance. The second must lie a median ``_DISTINCT_DEG``
    from the first family's vanishing point (and is sought among segments at least half that
    far): two orthogonal directions
    on a plane seen at a slant under 75 deg stay that far apart in the image (2 atan(cos
    slant), orthographic), while stones' sides and grass a few degrees off a curved row made
    false second families there. Deterministic for a given ``seed``.
    """
    rng = np.random.default_rng(seed)
    found, rest, share, first = [], s, 1.0, None
    for _ in range(2):
        pool = rest
        if first is not None:  # perspective brings single segments closer: half the angle
            pool = rest.take(_consistency(rest, first[None], side)[0]
                             >= math.radians(_DISTINCT_DEG / 2))
            share = 90.0 / (90.0 - _DISTINCT_DEG / 2)  # random directions in what is left
        result = _vanishing_point(pool, side, rng)
        if result is None:
            break
        vp, inliers = result
        family = pool.take(inliers)
        # Random directions would put this share of the length within the threshold.
        chance = (pool.length * np.minimum(1.0, 2.0 * share * (math.radians(_INLIER_DEG)
                                                               + 2.0 * pool.noise) / math.pi)
                  ).sum()
        if len(family) < _MIN_FAMILY or family.length.sum() < max(_MIN_SUPPORT * side,
                                                                  _OVER_CHANCE * chance):
            break
        if first is not None and np.median(_consistency(family, first[None], side)[0]) \
                < math.radians(_DISTINCT_DEG):
            break
        found.append(family)
        rest, first = pool.take(~inliers), vp
    return found


def vanishing_point(family: Segments, side: float) -> np.ndarray | None:
    """The family's vanishing point in centred y-up pixels, None when it is at infinity (the
    family's lines are parallel in the image within their noise)."""
    vp = np.linalg.svd(weighted_lines(family, side), full_matrices=False)[2][-1]
    spread = float(np.max(np.linalg.norm(family.m, axis=1))) / side + 1.0
    if abs(vp[2]) * 1e3 < spread * np.linalg.norm(vp[:2]):  # farther than 1000 image sides
        return None
    return vp[:2] / vp[2] * side


def distinct_lines(family: Segments, vp: np.ndarray, side: float) -> np.ndarray:
    """Labels of the family's distinct lines: the pieces of a broken joint and its two sides
    are one line, and they share its position and its wander.

    Parameters
    ----------
    family : Segments
        One family, centred y-up analysis pixels.
    vp : array (3,)
        Its vanishing point, homogeneous in pixels / ``side`` (:func:`weighted_lines`).
    side : float
        The analysis image's longer side (pixels).

    Returns
    -------
    array of int (N,)
        0, 1, ... by where each segment's line through ``vp`` passes the image centre; a new
        label at each gap over ``_SAME_LINE`` pixels.

    References
    ----------
    Burns, Hanson & Riseman 1986, "Extracting straight lines", sec. VI (segments grouped into
    lines).

    Examples
    --------
    Three horizontal joints (y = -40, 0, 40), each found as two pieces, one of them as its two
    sides 2 pixels apart; the vanishing point is at infinity along x:

    >>> m = np.array([[-50, -40], [50, -40], [-50, 0], [50, 0], [-50, 39], [-50, 41.0]])
    >>> family = Segments(m, np.tile([1.0, 0.0], (6, 1)), np.full(6, 60.0))
    >>> distinct_lines(family, np.array([1.0, 0.0, 0.0]), 320.0).tolist()
    [0, 0, 1, 1, 2, 2]
    """
    points = np.concatenate([family.m / side, np.ones((len(family), 1))], axis=1)
    through = np.cross(np.broadcast_to(vp, points.shape), points)
    through /= np.linalg.norm(through[:, :2], axis=1, keepdims=True)
    through *= np.sign(through[:, :2] @ through[int(np.argmax(family.weight)), :2])[:, None]
    offset = through[:, 2] * side
    order = np.argsort(offset)
    labels = np.empty(len(family), np.intp)
    labels[order] = np.concatenate([[0], np.cumsum(np.diff(offset[order]) > _SAME_LINE)])
    return labels


def horizon_through(family: Segments, side: float) -> np.ndarray:
    """The family's vanishing point as a constraint on the vanishing line v: (a, c) with
    a . v = c (a unit vector): every plane whose lines of this direction appear as the family
    has its horizon v . x = 1 through the vanishing point x (a . v = 0 when x is at infinity)."""
    vp = np.linalg.svd(weighted_lines(family, side), full_matrices=False)[2][-1]
    norm = float(np.linalg.norm(vp[:2]))
    return np.append(vp[:2] / norm, vp[2] / (norm * side))


def spaced_horizon(family: Segments, constraint: np.ndarray,
                   side: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The vanishing line v (1 / pixels) that makes the family's lines equally spaced on the
    plane (boards, courses, tile rows), searched along the family's own ``constraint``
    (:func:`horizon_through`), and its covariance (from the half-height width of the
    periodicity peak, two sigmas); None when no spacing stands out of chance.

    Under v, the plane offset across the family of an image point x is o = (m . x) / (1 - v . x)
    up to scale, m normal to the direction of the vanishing point; o is periodic in equally
    spaced lines (z: the Rayleigh statistic of the best period), and a wrong v chirps the period
    across the image. A family of fewer than ``_SPACED_LINES`` distinct lines
    (:func:`distinct_lines`) has no spacing to test: its pieces share their line's offset, so
    a joint broken into ten pieces would count as ten equally spaced ones (a phone photo of
    three paver joints, found as 29 pieces, passed the test at a wrong horizon).

    The sigma is the wider of the peak's half-height width and the profile likelihood's:
    z / D is the log-likelihood ratio of a periodic offset against none (the Rayleigh test,
    Mardia & Jupp 2000, sec. 6.3.1), D the design effect of pieces of one line sharing its
    phase (:func:`_design_effect`): the hypotheses about the peak within ``_SPACED_DROP`` of
    it are not ruled out (two sigmas), nor is the frontal view (t = 0 along the constraint)
    when it is within that too. Frontal granite setts, curved courses in pieces about five
    periods across, peaked at a horizon of slant 56 deg with a half-height sigma of 6 deg
    while the frontal horizon lay 1.6 log-units below the peak.
    """
    vp = np.linalg.svd(weighted_lines(family, side), full_matrices=False)[2][-1]
    labels = distinct_lines(family, vp, side)
    if labels.max(initial=-1) + 1 < _SPACED_LINES:
        return None
    a, c = constraint[:2], float(constraint[2])
    across = np.array([-a[1], a[0]])
    vp_dir = np.linalg.svd(_lines(family, side) * np.sqrt(family.length)[:, None],
                       full_matrices=False)[2][-1][:2]
    m = np.array([-vp_dir[1], vp_dir[0]])
    x, weight = family.m, family.length
    t = np.tan(np.radians(np.arange(-85.0, 85.1, 1.0))) * 2.0 / side
    z = np.zeros(len(t))
    for i, ti in enumerate(t):
        g = 1.0 - x @ (c * a + ti * across)
        if g.min() > _G_SPACED:
            # Periods counted over the central offsets: segments near the horizon (o grows as
            # 1 / g) would squeeze the rest into one period, periodic under any hypothesis.
            o = (x @ m) / g
            lo_o, hi_o = np.percentile(o, _CENTRAL)
            o = (o - lo_o) / max(float(hi_o - lo_o), 1e-12)
            rayleigh = np.abs(_phasor_sums(o, weight)) ** 2
            z[i] = rayleigh.max() / (weight * weight).sum()
    best = int(np.argmax(z))
    if z[best] < _SPACED_Z:
        return None
    lo, hi = best, best
    while lo > 0 and z[lo - 1] >= z[best] / 2:
        lo -= 1
    while hi < len(t) - 1 and z[hi + 1] >= z[best] / 2:
        hi += 1
    sd = max(t[hi] - t[lo], t[min(best + 1, len(t) - 1)] - t[max(best - 1, 0)]) / 4.0
    near = (z > 0) & ((z[best] - z) / _design_effect(family, labels) <= _SPACED_DROP)
    lo, hi = best, best
    while lo > 0 and near[lo - 1]:
        lo -= 1
    while hi < len(t) - 1 and near[hi + 1]:
        hi += 1
    frontal = int(np.argmin(np.abs(t)))  # t = 0: the horizon nearest the frontal view's
    reach = max(t[hi] - t[best], t[best] - t[lo], abs(t[best]) if near[frontal] else 0.0)
    sd = max(sd, float(reach) / 2.0)
    return c * a + t[best] * across, sd * sd * np.outer(across, across)


def _design_effect(family: Segments, labels: np.ndarray) -> float:
    """D = sum_l W_l^2 / sum_i w_i^2 (W_l the summed length of distinct line l, w_i a piece's):
    how many times the Rayleigh statistic over pieces overstates the one over lines when the
    pieces of a line share its phase (Kish 1965, sec. 5.4).

    Examples
    --------
    >>> family = Segments(np.zeros((4, 2)), np.tile([1.0, 0.0], (4, 1)), np.full(4, 10.0))
    >>> _design_effect(family, np.array([0, 0, 1, 1]))  # two lines, each in two pieces
    2.0
    """
    lengths = np.bincount(labels, family.length)
    return float((lengths ** 2).sum() / (family.length ** 2).sum())


def _phasor_sums(o: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """sum_n weight_n exp(2 pi i c o_n) for every period count c of ``_CYCLES``.

    With c_j = c_0 + j dc and j = a B + b, the phasor factors into exp(2 pi i (c_0 + a B dc) o)
    exp(2 pi i b dc o): the sums are the matrix product of about sqrt(len(_CYCLES)) coarse and
    as many fine phasors per offset (one BLAS call; 2 sqrt(C) exponentials an offset instead
    of C products of a recurrence over a (C, N) array: 3 to 4 times faster at 1000 to 3000
    segments, a brick wall's joined family; equal to 1e-13 of the peak).

    Examples
    --------
    >>> o, w = np.array([0.0, 0.5, 1.0]), np.array([1.0, 2.0, 1.0])
    >>> direct = np.exp(2j * np.pi * _CYCLES[:, None] * o) @ w
    >>> bool(np.allclose(_phasor_sums(o, w), direct, rtol=0, atol=1e-9))
    True
    """
    count, dc = len(_CYCLES), _CYCLES[1] - _CYCLES[0]
    fine_n = math.isqrt(count - 1) + 1
    coarse_n = -(-count // fine_n)
    coarse = np.exp(2j * math.pi * (_CYCLES[0] + np.arange(coarse_n) * (fine_n * dc))[:, None]
                    * o) * weight
    fine = np.exp(2j * math.pi * (np.arange(fine_n) * dc)[:, None] * o)
    return (coarse @ fine.T).ravel()[:count]


class LineCost:
    """Robust chi-square of a plane hypothesis against the families: each family's
    back-projected directions parallel, two families orthogonal (unless ``orthogonal`` is False:
    then the families only fix the vanishing line); noise per segment from :func:`_noise`, scaled
    by the scatter left at the best fit (``calibrate``).

    Each residual is a plane angle converted back to the image angle it comes from (divided by
    d(plane angle) / d(image angle) = det J / |J d|^2 at the segment): the noise is the image's,
    and a hypothesis cannot explain the lines by a slant so steep that it squeezes every
    direction onto the tilt. To first order this is the image-space consistency of Rother 2002
    that :func:`families` uses: the angle between a segment and the line from its midpoint to
    the hypothesis's vanishing point."""

    def __init__(self, found: list[Segments], orthogonal: bool = True):
        self.families = found
        self.sigma = [f.noise for f in found]
        self.scale = 1.0
        self.orthogonal = orthogonal

    def angles(self, p: np.ndarray, v: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """Plane directions (radians mod pi) of each family's segments under (p, v), and their
        sensitivity to the segments' image directions (d plane angle / d image angle)."""
        return [(angle, gain) for angle, gain, _ in self._mapped(p, v)]

    def _mapped(self, p: np.ndarray, v: np.ndarray):
        """:meth:`angles` and the local Jacobians of each family's segments."""
        out = []
        for f in self.families:
            jac, g = jacobians(f.m, p, v)
            j00, j01, j10, j11 = jac[:, 0, 0], jac[:, 0, 1], jac[:, 1, 0], jac[:, 1, 1]
            a = np.stack([j00 * f.d[:, 0] + j01 * f.d[:, 1], j10 * f.d[:, 0] + j11 * f.d[:, 1]],
                         axis=1)  # J d, and det J below, written out: 2 x 2 for each segment
            angle = np.arctan2(a[:, 1], a[:, 0])
            gain = (j00 * j11 - j01 * j10) / np.maximum((a * a).sum(axis=1), 1e-300)
            out.append((np.where(g > 0.05, angle, np.nan), np.where(g > 0.05, gain, 1.0), jac))
        return out

    def residuals(self, p: np.ndarray, v: np.ndarray) -> tuple[list[np.ndarray], float | None]:
        """Each family's image-angle residuals (radians) about its plane direction, and the
        orthogonality residual (plane radians; None for one family).

        A residual is the image angle between the segment and the family's plane direction
        mapped into the image at its midpoint (J^-1 u), exactly, not the plane angle divided by
        the gain: to first order the same, but at a steep slant the linearisation shrank the
        residuals of stray segments far from the family's direction, and a slant of 85 deg
        near orthographic fitted a frontal photo's lines better than the frontal view."""
        means, out = [], []
        for (angle, gain, jac), sigma, f in zip(self._mapped(p, v), self.sigma, self.families,
                                                 strict=True):
            ok = np.isfinite(angle)
            weight = np.where(ok, 1.0 / (gain * sigma) ** 2, 0.0)
            doubled = np.where(ok, 2.0 * angle, 0.0)
            mean = 0.5 * math.atan2((np.sin(doubled) * weight).sum(),
                                    (np.cos(doubled) * weight).sum())
            # J^-1 u by the adjugate (det J > 0 where g > 0): the image direction of u.
            u = (math.cos(mean), math.sin(mean))
            pred_x = jac[:, 1, 1] * u[0] - jac[:, 0, 1] * u[1]
            pred_y = jac[:, 0, 0] * u[1] - jac[:, 1, 0] * u[0]
            miss = np.arctan2(pred_x * f.d[:, 1] - pred_y * f.d[:, 0],
                              pred_x * f.d[:, 0] + pred_y * f.d[:, 1])
            out.append(np.where(ok, (miss + math.pi / 2) % math.pi - math.pi / 2, math.pi / 2))
            means.append(mean)
        ortho = None
        if len(means) == 2:
            ortho = (means[0] - means[1]) % math.pi - math.pi / 2
        return out, ortho

    def __call__(self, p: np.ndarray, v: np.ndarray) -> float:
        """Robust chi-square: a segment or an orthogonality that misses by more than
        ``_ROBUST`` sigmas (a stray segment, a false family) stops pulling."""
        residual, ortho = self.residuals(p, v)
        chi2 = sum(float(robust((r / s) ** 2 / self.scale).sum())
                   for r, s in zip(residual, self.sigma, strict=True))
        if ortho is not None and self.orthogonal:
            chi2 += float(robust((ortho / math.radians(ORTHOGONAL_DEG)) ** 2))
        return chi2

    def calibrate(self, p: np.ndarray, v: np.ndarray) -> None:
        """Scale the segments' noise so that their median squared residual at (p, v) is that of
        a chi-square with one degree of freedom (never below the pixel noise of :func:`_noise`)."""
        residual, _ = self.residuals(p, v)
        z2 = np.concatenate([(r / s) ** 2 for r, s in zip(residual, self.sigma, strict=True)])
        self.scale = max(1.0, float(np.median(z2)) / 0.455)


def robust(z2):
    """Cauchy loss of squared standardised residuals: z^2 near 0, logarithmic beyond _ROBUST."""
    return _ROBUST ** 2 * np.log1p(np.asarray(z2) / _ROBUST ** 2)
