"""The joint network of a man-made surface: where its elements (bricks, setts, pavers) meet.

A joint is a line darker (or brighter) than the elements either side of it, a valley (a ridge)
of the luminance at the joint's width. It is found by the Hessian of the luminance at scale
``sigma``, Lindeberg 1998, 4 ("Edge detection and ridge detection with automatic scale
selection"): the eigenvalues ``lambda_1 >= lambda_2`` of the Gaussian second derivatives,
normalised by ``sigma^2`` (for a bar of width ``w`` the response peaks at ``sigma = w / 2``);
a dark line has ``lambda_1`` large and positive across it, a bright one ``lambda_2`` large and
negative. :meth:`Joints.fit` fixes the rule on the photo, given the joints' half width: the
polarity (the one whose strongest ``TOP`` is the stronger) and the threshold (Otsu 1979 on the
response); :meth:`Joints.mask` applies the same rule to any image made of the photo's pixels.
The mask thinned to one pixel (Zhang & Suen 1984, the two sub-iterations, every pixel at once)
is the network's skeleton; its spurs shorter than the joint's width are pruned (Gonzalez &
Woods 2008, 9.5.8: ends eroded, then regrown along the skeleton). A dead end is a skeleton
pixel with exactly one of its 8 neighbours in the skeleton: where a joint stops, inside an element.

Deviations, one line each:
- the scale is the caller's (the joints' half width): Lindeberg's automatic selection chose
  the grain of the concrete pavers and the brick wall's lighting, not their joints;
- the work is done at the feature scale: the luminance's ``f`` x ``f`` block means, ``f`` the
  largest power of two keeping ``sigma / f`` at least ``FINE`` (a 12 MP photo's joints are
  tens of pixels wide);
- components of the mask smaller than ``MIN_AREA`` (in ``(sigma / f)^2``) are grain, not joints:
  left out;
- a photo that does not tile is read mirrored at its edges (a joint reaching the edge runs on,
  not a dead end); a periodic output is read on the torus, its components' areas and the
  spurs' regrowth too (read on the array, a joint across its edges split into pieces under
  ``MIN_AREA`` or stopped there: make_tileable's outputs of the brick wall 1024, seeds 0-5,
  read a dead-end ratio of 1.11-1.15 as they are, 1.14-1.18 rolled by (300, 700); on the
  torus 1.10-1.14 wherever the wrap falls).

The joints' scale, measured (:func:`joint_scale`): at each scale of a ladder a half octave
apart the rule above is fitted and its skeleton's directions read (the Hessian's, the line
across the larger eigenvalue's eigenvector); a man-made surface's joints run in two families at
right angles (courses and heads, rows and columns), a stochastic surface's gaps every way. The
two families' coherence is the double-angle representation (Granlund 1978; Bigun & Granlund
1987: an orientation ``theta`` as ``exp(2 i theta)``) doubled once more, ``C = |mean exp(4 i
theta)|`` over the skeleton, 1 for lines all at 0 and 90 degrees (any rotation), 0 for every
direction alike; the joints' half width is the finest scale where ``C`` is within
``NEAR_BEST`` of its largest, and there are none where it stays under ``COHERENCE``. One
line each: the ladder runs from a pixel to a ``WIDEST``-th of the shorter side; each scale
is read on a centre sample at most ``SAMPLE`` working pixels square (a 12 MP photo's
1.4-pixel scale reads 512 x 512 pixels, not 12 M: 0.3-0.5 s CPU for 512 to 2048 px photos);
lattices of three families (hexagonal tiles) read low and are not found.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage, sparse
from scipy.sparse import csgraph

__all__ = ["Joints", "luma", "reduce", "thin", "prune", "ends", "coherence", "joint_scale",
           "joint_mask"]

#: Share of the strongest response that chooses the polarity.
TOP = 0.1
#: The least joint half width, in pixels at the working scale.
FINE = 1.5
#: Least component of the joint mask, in units of (sigma / f)^2.
MIN_AREA = 64.0
#: Least coherence of a joint network's two families (``coherence``): the shared stochastic
#: photos' 512 crops (gravel, layered rock, asphalt, lawn, gravelly dirt, jagged cliff) read at
#: most 0.33 at any scale, bricks, pavers, setts, ashlar and flagstones 0.48-0.91 at theirs.
COHERENCE = 0.4
#: The joints' scale is the finest whose coherence is at least this share of the best: a
#: course or a whole element reads as a bar at a coarse scale, as coherent (the 1024 brick
#: wall: 0.83 at 1.4 px, 0.91 at 22.6 px, its courses), and the joint is the finest.
NEAR_BEST = 0.9
#: The side (working pixels) of the centre sample each scale is read on.
SAMPLE = 512
#: The widest scale tried, as a share of the shorter side (a joint then spans 1/16 of it).
WIDEST = 1 / 32


def luma(image: np.ndarray) -> np.ndarray:
    """Rec. 709 luma (float32) of an (H, W), (H, W, 1) or (H, W, C >= 3) array."""
    a = np.asarray(image, np.float32)
    if a.ndim == 2:
        return a
    if a.shape[2] >= 3:
        return np.einsum("ijc,c->ij", a[:, :, :3], np.array([0.2126, 0.7152, 0.0722],
                                                             np.float32))
    return a[:, :, 0]


def reduce(y: np.ndarray, f: int) -> np.ndarray:
    """The float32 means of the ``f`` x ``f`` blocks of ``y`` (the last partial blocks left out).

    Examples
    --------
    >>> reduce(np.arange(16.0).reshape(4, 4), 2).tolist()
    [[2.5, 4.5], [10.5, 12.5]]
    """
    if f == 1:
        return np.asarray(y, np.float32)
    h, w = y.shape[0] // f, y.shape[1] // f
    return y[:h * f, :w * f].reshape(h, f, w, f).mean(axis=(1, 3), dtype=np.float32)


def _hessian(y: np.ndarray, sigma: float, wrap: bool) -> tuple[np.ndarray, ...]:
    """The Gaussian second derivatives (yy, xx, xy) of ``y`` at scale ``sigma``."""
    mode = "wrap" if wrap else "reflect"
    return tuple(ndimage.gaussian_filter(y, sigma, order=o, mode=mode)
                 for o in ((2, 0), (0, 2), (1, 1)))


def _response(y: np.ndarray, sigma: float, wrap: bool,
              hessian: tuple[np.ndarray, ...] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(dark, bright): the sigma^2-normalised Hessian responses of dark and bright lines."""
    yy, xx, xy = _hessian(y, sigma, wrap) if hessian is None else hessian
    mean, root = (xx + yy) / 2, np.hypot((xx - yy) / 2, xy)
    s2 = np.float32(sigma * sigma)
    return np.maximum(mean + root, 0) * s2, np.maximum(root - mean, 0) * s2


def _otsu(values: np.ndarray, bins: int = 256) -> float:
    """Otsu 1979: the threshold that maximises the between-class variance of ``values``
    (their one value when they are all equal: nothing lies above it)."""
    if np.ptp(values) == 0:
        return float(values.flat[0])
    count, edges = np.histogram(values, bins)
    centre = (edges[:-1] + edges[1:]) / 2
    w0 = np.cumsum(count)
    m0 = np.cumsum(count * centre)
    w1, m1 = w0[-1] - w0, m0[-1] - m0
    with np.errstate(divide="ignore", invalid="ignore"):
        between = w0 * w1 * (m0 / w0 - m1 / w1) ** 2
    return float(centre[int(np.nanargmax(np.where(w1 > 0, between, np.nan)))])


#: P2..P9 of Zhang & Suen 1984 (N, NE, E, SE, S, SW, W, NW): their (row, col) in a pixel's
#: 3 x 3 neighbourhood, bit k of a pixel's neighbourhood code (:func:`_code`) telling P(k + 2).
_AROUND = ((0, 1), (0, 2), (1, 2), (2, 2), (2, 1), (2, 0), (1, 0), (0, 0))


def _code(a: np.ndarray) -> np.ndarray:
    """Every pixel's 8 neighbours (bool ``a``, on the torus) as the bits of one uint8."""
    p = np.pad(a.view(np.uint8), 1, mode="wrap")
    h, w = a.shape
    code = p[0:h, 1:w + 1].copy()
    for k, (i, j) in enumerate(_AROUND[1:], 1):
        code |= p[i:i + h, j:j + w] << k
    return code


def _removal_tables() -> tuple[np.ndarray, np.ndarray]:
    """Zhang & Suen 1984's rule for each sub-iteration, over the 256 neighbourhood codes: the
    pixel goes when 2 <= B(P1) <= 6, A(P1) = 1 (one 0 -> 1 transition round P2..P9, P2) and
    not P2 P4 P6 nor P4 P6 P8 (the first; the second: not P2 P4 P8 nor P2 P6 P8)."""
    p = (np.arange(256)[None, :] >> np.arange(8)[:, None]) & 1 == 1
    b = p.sum(axis=0)
    transitions = (~p & np.roll(p, -1, axis=0)).sum(axis=0)
    n, e, s, w = p[0], p[2], p[4], p[6]
    base = (b >= 2) & (b <= 6) & (transitions == 1)
    return base & ~((n & e & s) | (e & s & w)), base & ~((n & e & w) | (n & s & w))


_REMOVAL = _removal_tables()
#: A neighbourhood code's count of neighbours.
_DEGREE = np.array([bin(code).count("1") for code in range(256)], np.uint8)


def thin(mask: np.ndarray) -> np.ndarray:
    """Zhang & Suen 1984's thinning of a bool mask on the torus, each sub-iteration on every
    pixel at once: a one-pixel-wide skeleton (the rule read from a table of the 256
    neighbourhoods, :func:`_removal_tables`).

    Examples
    --------
    >>> bar = np.zeros((9, 12), bool); bar[3:6, 2:10] = True
    >>> thin(bar).sum(axis=0).tolist()  # one row, a pixel shorter at either end
    [0, 0, 0, 1, 1, 1, 1, 1, 0, 0, 0, 0]
    """
    a = np.asarray(mask, bool).copy()
    while True:
        changed = False
        for removal in _REMOVAL:
            gone = a & removal[_code(a)]
            if gone.any():
                a &= ~gone
                changed = True
        if not changed:
            return a


def _degree(skeleton: np.ndarray) -> np.ndarray:
    return _DEGREE[_code(skeleton)]


def ends(skeleton: np.ndarray) -> np.ndarray:
    """The skeleton's dead ends: its pixels with exactly one of their 8 neighbours in it."""
    return skeleton & (_degree(skeleton) == 1)


def prune(skeleton: np.ndarray, k: int, wrap: bool = False) -> np.ndarray:
    """Gonzalez & Woods 2008, 9.5.8: the spurs of the skeleton up to ``k`` pixels long removed
    (its ends eroded ``k`` times, the ends left then regrown ``k`` times along the skeleton;
    on the torus with ``wrap``).

    Examples
    --------
    >>> s = np.zeros((9, 16), bool); s[4, 1:15] = True; s[1:4, 8] = True  # a line, a 3 px spur
    >>> int(ends(s).sum()), int(ends(prune(s, 4)).sum())
    (3, 2)
    """
    a = skeleton.copy()
    for _ in range(k):
        a &= ~ends(a)
    tips = ends(a)  # regrown k steps through the removed pixels only (scipy's own iterations)
    if not wrap:
        return a | ndimage.binary_dilation(tips, np.ones((3, 3), bool), k, skeleton & ~a | tips)
    # On the torus: k steps reach at most k pixels, so k rows and columns wrapped around do.
    h, w = a.shape
    grown = ndimage.binary_dilation(np.pad(tips, k, mode="wrap"), np.ones((3, 3), bool), k,
                                    np.pad(skeleton & ~a | tips, k, mode="wrap"))
    return a | grown[k:k + h, k:k + w]


def coherence(image: np.ndarray, sigma: float) -> float:
    """The coherence ``C`` of two families of lines at right angles (see the module notes) of
    the joints of half width ``sigma`` that ``Joints.fit(image, sigma)`` reads in ``image``: 1
    where every joint runs at one angle or at right angles to it, 0 with none or every
    direction alike.

    References
    ----------
    Granlund 1978, Bigun & Granlund 1987 (the double-angle representation of orientation);
    Lindeberg 1998, 4 (the Hessian's directions at a ridge).

    Examples
    --------
    >>> i, j = np.mgrid[:128, :128]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> rings = np.where(np.hypot(i - 64, j - 64) % 16 < 3, 0.2, 0.7)
    >>> round(coherence(wall, 1.5), 1), round(coherence(rings, 1.5), 1)
    (0.9, 0.2)
    """
    f = Joints.block(sigma)
    y = reduce(luma(image), f)
    yy, xx, xy = hessian = _hessian(y, sigma / f, wrap=False)
    response = _response(y, sigma / f, False, hessian)
    joints = Joints.rule(response, sigma, f)
    skeleton, _ = joints.skeleton(image, joint=joints.select(response))
    if not skeleton.any():
        return 0.0
    theta = 0.5 * np.arctan2(2 * xy[skeleton], xx[skeleton] - yy[skeleton])
    return float(np.abs(np.exp(4j * theta).mean()))


def joint_mask(photo: np.ndarray, sigma: float) -> np.ndarray:
    """``Joints.fit(photo, sigma).mask(photo)`` from one response: the joints of half width
    ``sigma`` that the rule fixed on ``photo`` reads in it (bool, the working scale).

    Examples
    --------
    >>> i, j = np.mgrid[:96, :128]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> bool((joint_mask(wall, 1.5) == Joints.fit(wall, 1.5).mask(wall)).all())
    True
    """
    f = Joints.block(sigma)
    response = _response(reduce(luma(photo), f), sigma / f, wrap=False)
    return Joints.rule(response, sigma, f).select(response)


def joint_scale(photo: np.ndarray) -> float | None:
    """The half width (photo pixels) of ``photo``'s joints, the finest scale of the ladder
    ``2^(k/2)`` at which their two families are nearly (``NEAR_BEST``) as coherent as at best
    (:func:`coherence`, each scale on a centre sample of ``SAMPLE`` working pixels), or
    ``None`` where no scale reaches ``COHERENCE`` (a stochastic photo: gravel, rock, grass).

    Examples
    --------
    >>> i, j = np.mgrid[:256, :256]
    >>> wall = np.where((i % 24 < 4) | ((j + 24 * (i // 24 % 2)) % 48 < 4), 0.2, 0.7)
    >>> joint_scale(wall)  # joints 4 px wide: coherent from 1 px on (the finest is taken)
    1.0
    >>> print(joint_scale(np.random.default_rng(0).random((256, 256))))
    None
    """
    y = luma(photo)
    h, w = y.shape
    scales, c = [], []
    while 2 ** (len(scales) / 2) <= WIDEST * min(h, w):
        sigma = 2 ** (len(scales) / 2)
        side = SAMPLE * Joints.block(sigma)
        top, left = max(0, (h - side) // 2), max(0, (w - side) // 2)
        c.append(coherence(y[top:top + side, left:left + side], sigma))
        scales.append(sigma)
    if not c or max(c) < COHERENCE:
        return None
    return scales[next(i for i, v in enumerate(c) if v >= NEAR_BEST * max(c))]


@dataclass(frozen=True)
class Joints:
    """The rule that reads a photo's joints, fixed on the photo: the scale ``sigma`` (photo
    pixels), the working block size ``f``, the polarity (``dark``) and the threshold.

    Examples
    --------
    >>> i, j = np.mgrid[:96, :128]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> joints = Joints.fit(wall, sigma=1.5)
    >>> joints.dark, bool(joints.mask(wall)[1, 10]), bool(joints.mask(wall)[8, 10])
    (True, True, False)
    """

    sigma: float
    f: int
    dark: bool
    threshold: float

    @classmethod
    def fit(cls, photo: np.ndarray, sigma: float) -> Joints:
        """The rule that reads ``photo``'s joints of half width ``sigma`` (pixels): the
        polarity whose strongest ``TOP`` of the response is the stronger, Otsu's threshold."""
        f = cls.block(sigma)
        return cls.rule(_response(reduce(luma(photo), f), sigma / f, wrap=False), sigma, f)

    @classmethod
    def rule(cls, response: tuple[np.ndarray, np.ndarray], sigma: float, f: int) -> Joints:
        """:meth:`fit`'s rule from the photo's (dark, bright) responses at the working scale."""
        dark, bright = response
        is_dark = bool(np.quantile(dark, 1 - TOP) >= np.quantile(bright, 1 - TOP))
        return cls(float(sigma), f, is_dark, _otsu(dark if is_dark else bright))

    @staticmethod
    def block(sigma: float) -> int:
        """The largest power of two ``f`` with ``sigma / f`` at least ``FINE``."""
        f = 1
        while sigma / (2 * f) >= FINE:
            f *= 2
        return f

    def mask(self, image: np.ndarray, wrap: bool = False) -> np.ndarray:
        """The joints of ``image`` (bool, at the working scale: ``H // f`` x ``W // f``), read
        on the torus when ``wrap``; components under ``MIN_AREA`` left out."""
        return self.select(_response(reduce(luma(image), self.f), self.sigma / self.f, wrap),
                           wrap)

    def select(self, response: tuple[np.ndarray, np.ndarray], wrap: bool = False
               ) -> np.ndarray:
        """:meth:`mask` from an image's (dark, bright) responses at the working scale; with
        ``wrap``, a component's area counted on the torus (its parts at opposite edges one)."""
        joint = response[0 if self.dark else 1] > self.threshold
        labels, n = ndimage.label(joint)
        if n == 0:
            return joint
        if wrap:  # the labels that meet across the wrap (4-neighbours, as ndimage.label's)
            a, b = np.concatenate([labels[0], labels[:, 0]]), np.concatenate(
                [labels[-1], labels[:, -1]])
            meet = (a > 0) & (b > 0)
            graph = sparse.coo_matrix((np.ones(meet.sum()), (a[meet], b[meet])), (n + 1, n + 1))
            root = csgraph.connected_components(graph, directed=False)[1]
            labels = np.where(labels > 0, root[labels] + 1, 0)
            n = int(labels.max())
        area = np.bincount(labels.ravel(), minlength=n + 1)
        keep = area >= MIN_AREA * (self.sigma / self.f) ** 2
        keep[0] = False
        return keep[labels]

    def skeleton(self, image: np.ndarray, wrap: bool = False,
                 joint: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The joint network's pruned skeleton and its dead ends (bool, the working scale); a
        photo that does not tile (``wrap`` false) is read mirrored at its edges (a joint that
        reaches an edge runs on), the photo's part of both returned. ``joint``: its
        :meth:`mask`, when already made."""
        joint = self.mask(image, wrap) if joint is None else joint
        m = 0 if wrap else int(np.ceil(4 * self.sigma / self.f)) + 2
        if m:
            joint = np.pad(joint, m, mode="symmetric")
        k = max(1, int(np.ceil(2 * self.sigma / self.f)))
        s = prune(thin(joint), k, wrap=not m)
        e = ends(s)
        if not m:
            return s, e
        return s[m:len(s) - m, m:s.shape[1] - m], e[m:len(s) - m, m:s.shape[1] - m]
