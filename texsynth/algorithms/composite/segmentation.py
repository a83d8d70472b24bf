"""Unsupervised segmentation of a composite texture into subtextures, and label images.

Zalesny et al. 2002, section 3: "Segmentation based on Lab color data ... smoothed with a Gaussian
filter of size 5x5 ... an additional vector ... of simple texture features, obtained as the outputs
of a bank of simple filters. A cosine metric between such feature vectors is used as similarity ...
A sample pixel set is drawn from the image and a complete graph is constructed ... partitioned
into completely connected, disjoint subsets of vertices so as to maximize the total sum of the
similarities over all remaining edges" (clique partitioning, which needs no number of classes).

    features f(p): Lab of the 5 x 5 Gaussian-smoothed image (+ optional filter-bank energies);
    sample ``samples`` pixels; w_ij = cosine similarity of their feature vectors;
    partition the sample graph greedily: start from single vertices, merge the two groups whose
    edges between them sum highest while that sum is positive, then move single vertices to the
    group they gain most from, until no move gains;
    label every pixel with the group whose mean (unit) feature vector is most similar.

Deviations, one line each:
- the cosine is taken between centred feature vectors with one constant component ``contrast``
  (in Lab units) appended: a plain cosine of Lab vectors would call any two colours of one hue
  similar; centred without the constant, it would split even a uniform texture in two. With it,
  two groups separate when their colours lie about 2 x ``contrast`` apart or more; by default
  the contrast is lowered from 6 to 3 to 2 Lab units until two classes or more appear (a
  composite texture has at least two), so low-contrast mixtures are split too;
- the centre is the mid-range (2nd and 98th percentiles), so it does not follow class proportions;
- the greedy merge-then-move heuristic stands in for the approximation algorithm of the paper's
  reference [4];
- groups holding less than ``min_fraction`` of the pixels are dropped (their pixels go to the
  next most similar group);
- an image of more than ``SAMPLE_PIXELS`` pixels: the centre, the sample graph's vertices and
  the class shares come from a regular sample of ``SAMPLE_PIXELS`` of its pixels (then every
  pixel is labelled).

References
----------
Zalesny et al. 2002, section 3 (segmentation by clique partitioning of a sample graph).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from ... import validation
from ...blocks.color import srgb_to_linear
from ...blocks.parallel import run, small_product

__all__ = ["lab", "features", "partition", "segment", "labels_from_image", "label_colours",
           "MAX_CLASSES"]

#: Most classes a label map may have (the label texture's marks: ``cooccurrence.cliques.GOLOMB``).
MAX_CLASSES = 12
SAMPLES = 400
#: 0 is automatic: the first of ``AUTO_CONTRASTS`` that finds two classes or more.
CONTRAST = 0.0
AUTO_CONTRASTS = (6.0, 3.0, 2.0)
MIN_FRACTION = 0.02
#: 5 x 5 Gaussian of the paper: sigma 1 truncated at 2 pixels.
SIGMA, RADIUS = 1.0, 2
#: Rows the texture features reach: a derivative (1) under a Gaussian of sigma 3 cut at 4 sigma.
TEXTURE_MARGIN = 13
#: Rows of the image computed at once (features) and pixels labelled at once.
BAND, CHUNK = 256, 1 << 18
#: Pixels of a larger image its feature centre and sample graph are drawn from.
SAMPLE_PIXELS = 1 << 20

_RGB_TO_XYZ = np.array([[0.4124, 0.3576, 0.1805],
                        [0.2126, 0.7152, 0.0722],
                        [0.0193, 0.1192, 0.9505]], np.float32)
_WHITE = np.array([0.9505, 1.0, 1.089], np.float32)


def lab(image: np.ndarray) -> np.ndarray:
    """CIE Lab (D65) of an sRGB-encoded (H, W, C) image in [0, 1]; grey is taken as R = G = B."""
    rgb = np.asarray(image, np.float32)
    rgb = np.repeat(rgb[:, :, :1], 3, axis=2) if rgb.shape[2] < 3 else rgb[:, :, :3]
    xyz = srgb_to_linear(np.clip(rgb, 0.0, 1.0)) @ _RGB_TO_XYZ.T / _WHITE
    f = np.where(xyz > (6 / 29) ** 3, np.cbrt(xyz), xyz / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.stack([116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]),
                     200 * (f[..., 1] - f[..., 2])], axis=2).astype(np.float32)


def features(image: np.ndarray, texture: bool = False, tick=None) -> np.ndarray:
    """Per-pixel feature vectors (H, W, F): smoothed Lab, plus filter-bank energies if asked.

    The filter bank: local energy (Gaussian sigma 3) of the horizontal and vertical derivatives
    and of the Laplacian of L, in L units, so a smooth and a rough patch of one colour differ.
    Computed in bands of ``BAND`` rows on every core, each with the rows its filters reach
    (periodically) around it: the same numbers as the whole image at once. ``tick()``, when
    given, is called after each band (where a caller may cancel).
    """
    a = np.asarray(image, np.float32)
    h, w = a.shape[:2]
    out = np.empty((h, w, 6 if texture else 3), np.float32)
    margin = TEXTURE_MARGIN if texture else RADIUS

    def band(rows):
        y0, y1 = rows
        if y1 - y0 == h:
            out[:] = _features(a, texture)
            return
        window = np.take(a, np.arange(y0 - margin, y1 + margin) % h, axis=0)
        out[y0:y1] = _features(window, texture)[margin:margin + y1 - y0]

    run(band, [(y, min(y + BAND, h)) for y in range(0, h, BAND)], tick)
    return out


def _features(image: np.ndarray, texture: bool) -> np.ndarray:
    """:func:`features` of one image (or band), periodic."""
    f = lab(image)
    smooth = np.stack([ndimage.gaussian_filter(f[:, :, c], SIGMA, truncate=RADIUS / SIGMA,
                                               mode="wrap") for c in range(3)], axis=2)
    if not texture:
        return smooth
    light = f[:, :, 0]
    bank = [ndimage.sobel(light, axis=1, mode="wrap") / 8,
            ndimage.sobel(light, axis=0, mode="wrap") / 8,
            ndimage.laplace(light, mode="wrap") / 4]
    energy = [np.sqrt(ndimage.gaussian_filter(b * b, 3.0, mode="wrap")) for b in bank]
    return np.concatenate([smooth, np.stack(energy, axis=2)], axis=2).astype(np.float32)


def _unit(f: np.ndarray, centre: np.ndarray, contrast: float) -> np.ndarray:
    v = np.concatenate([f - centre, np.full(f.shape[:-1] + (1,), contrast, np.float32)], axis=-1)
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(norm > 0, norm, 1)  # a zero vector (contrast 0 at the centre) stays 0


def partition(w: np.ndarray) -> np.ndarray:
    """Greedy clique partitioning of a complete graph with edge weights ``w`` (n, n), symmetric.

    Maximises the sum of the weights inside the groups, with no number of groups given: merge
    the two groups with the largest positive weight between them until none is positive, then
    move single vertices to the group they gain most from until no move gains. Returns the group
    of each vertex (0, 1, ... in order of first vertex).
    """
    n = len(w)
    between = w.astype(np.float64).copy()
    np.fill_diagonal(between, -np.inf)
    group = np.arange(n)
    alive = np.ones(n, bool)
    while True:
        flat = int(np.argmax(between))
        a, b = divmod(flat, n)
        if not between[a, b] > 0:
            break
        a, b = min(a, b), max(a, b)
        between[a] += between[b]
        between[:, a] += between[:, b]
        between[a, a] = -np.inf
        between[b] = -np.inf
        between[:, b] = -np.inf
        group[group == b] = a
        alive[b] = False
    _, group = np.unique(group, return_inverse=True)
    w0 = w.astype(np.float64).copy()
    np.fill_diagonal(w0, 0.0)
    for _ in range(10):
        moved = False
        for i in range(n):
            gain = np.bincount(group, weights=w0[i], minlength=group.max() + 2)
            best = int(np.argmax(gain))
            if gain[best] > gain[group[i]] + 1e-12:
                group[i] = best
                moved = True
        _, group = np.unique(group, return_inverse=True)
        if not moved:
            break
    _, first = np.unique(group, return_index=True)
    rank = np.argsort(np.argsort(first))
    return rank[group].astype(np.int32)


def segment(image, *, samples: int = SAMPLES, contrast: float = CONTRAST, texture: bool = False,
            min_fraction: float = MIN_FRACTION, seed: int | np.random.Generator = 0,
            tick=None) -> np.ndarray:
    """Labels int32 (H, W), 0..K-1 with K found by the partitioning, largest class first.

    ``image``: sRGB-encoded (H, W) or (H, W, C) in [0, 1]. ``samples``: vertices of the sample
    graph. ``contrast``: the constant feature component (Lab units; larger merges more; 0:
    automatic, see the module notes). ``texture``: add the filter-bank features. ``tick()``,
    when given, is called every few rows (where a caller may cancel).
    """
    a = validation.image(image, what="the image to segment", min_side=4)
    contrast = validation.number(contrast, "contrast (Lab units; 0: automatic)", 0.0, 100.0)
    f = features(a, texture, tick)
    for c in AUTO_CONTRASTS if contrast == 0 else (contrast,):
        labels = _segment(f, samples, c, min_fraction, np.random.default_rng(seed), tick)
        if labels.max() > 0:
            break
    return labels


def _segment(f: np.ndarray, samples: int, contrast: float, min_fraction: float,
             rng: np.random.Generator, tick=None) -> np.ndarray:
    """:func:`segment` at one contrast, on the features ``f`` (H, W, F). The centre, the sample
    graph and the class shares come from every ``step``-th pixel (every pixel up to
    ``SAMPLE_PIXELS``); every pixel is then labelled, ``CHUNK`` at a time."""
    h, w, k = f.shape
    flat = f.reshape(-1, k)
    sample = flat[::-(-flat.shape[0] // SAMPLE_PIXELS)]
    lo, hi = np.percentile(sample, [2, 98], axis=0)
    centre = ((lo + hi) / 2).astype(np.float32)
    pick = rng.choice(sample.shape[0], size=min(samples, sample.shape[0]), replace=False)
    v = _unit(sample[pick], centre, contrast)
    group = partition(v @ v.T)
    means = np.stack([v[group == g].mean(axis=0) for g in range(group.max() + 1)])
    norm = np.linalg.norm(means, axis=1, keepdims=True)
    means /= np.where(norm > 0, norm, 1)

    def nearest(pixels, keep):
        similarity = small_product("nf,gf->ng", _unit(pixels, centre, contrast), means)
        return np.where(keep, similarity, -np.inf).argmax(axis=1)

    keep = np.ones(len(means), bool)
    while True:
        share = np.bincount(nearest(sample, keep), minlength=len(means)) / sample.shape[0]
        small = keep & (share < min_fraction)
        if not small.any() or keep.sum() == 1:
            break
        keep[np.flatnonzero(small)[np.argmin(share[small])]] = False
    labels = np.empty(flat.shape[0], np.int64)

    def label(a):
        labels[a:a + CHUNK] = nearest(flat[a:a + CHUNK], keep)

    run(label, range(0, flat.shape[0], CHUNK), tick)
    order = np.argsort(-np.bincount(labels, minlength=len(means)), kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return rank[labels].reshape(h, w).astype(np.int32)


def labels_from_image(image, min_share: float = 0.005) -> np.ndarray:
    """Labels int32 (H, W) from a painted label image, one flat colour per class.

    ``image``: (H, W) integer labels (taken as they are, renumbered 0..K-1 in order of value) or
    an (H, W, C) colour image. Colours on fewer than ``min_share`` of the pixels (anti-aliased
    edges) join the nearest frequent colour. Raises ``ValueError`` above ``MAX_CLASSES`` classes.
    """
    a = np.asarray(image)
    if a.ndim == 3 and a.shape[2] == 1:
        a = a[:, :, 0]
    if a.ndim == 2:
        _, labels = np.unique(a, return_inverse=True)
        labels = labels.reshape(a.shape)
    elif a.ndim == 3:
        colours, labels = np.unique(a[:, :, :3].reshape(-1, min(a.shape[2], 3)), axis=0,
                                    return_inverse=True)
        labels = labels.reshape(a.shape[:2])
        share = np.bincount(labels.ravel()) / labels.size
        major = np.flatnonzero(share >= min_share)
        if major.size == 0:
            raise ValueError("the label image has no colour covering "
                             f"{min_share:.1%} of its pixels; paint flat colours")
        c = colours.astype(np.float64)
        nearest = major[np.argmin(((c[:, None] - c[major][None]) ** 2).sum(axis=2), axis=1)]
        _, labels = np.unique(nearest[labels], return_inverse=True)
        labels = labels.reshape(a.shape[:2])
    else:
        raise ValueError(f"a label image is (H, W) or (H, W, C), got shape {a.shape}")
    classes = int(labels.max()) + 1
    if classes > MAX_CLASSES:
        raise ValueError(f"the label image has {classes} classes; at most {MAX_CLASSES} are "
                         "supported (paint fewer flat colours)")
    return labels.astype(np.int32)


def label_colours(labels: np.ndarray, exemplar: np.ndarray | None = None) -> np.ndarray:
    """An RGB float32 picture of a label map: each class in the mean colour of its exemplar
    pixels (when ``exemplar`` is given) or in a fixed palette colour."""
    labels = np.asarray(labels)
    classes = int(labels.max()) + 1
    if exemplar is not None:
        x = np.asarray(exemplar, np.float32)
        x = np.repeat(x[:, :, :1], 3, axis=2) if x.shape[2] < 3 else x[:, :, :3]
        count = np.maximum(np.bincount(labels.ravel(), minlength=classes), 1)[:, None]
        palette = np.stack([np.bincount(labels.ravel(), weights=x[:, :, c].ravel(),
                                        minlength=classes) for c in range(3)], axis=1) / count
    else:
        hue = np.arange(classes) * 0.618034 % 1.0
        palette = 0.5 + 0.45 * np.cos(2 * np.pi * (hue[:, None] + np.array([0, 1, 2]) / 3))
    return palette.astype(np.float32)[labels]
