"""Composite textures: a label texture filled with subtextures that interact near boundaries.

Zalesny et al. 2002, sections 1, 3 and 4::

    image = texsynth.synthesize(exemplar, 512, 512, method="composite")   # all automatic
    result = texsynth.composite.compose(exemplar, 512, 512, labels=mask,
                                        output_labels=painted_layout)
    result.image, result.labels, result.output_labels

1. Segment the exemplar: ``labels`` painted by the user (one flat colour per class), or the
   unsupervised segmentation of section 3 (:func:`.segmentation.segment`).
2. Model the label map as a texture: the clique model of section 2 on label marks
   (:func:`texsynth.cooccurrence.model.fit_labels`).
3. Model each subtexture from its own pixels only.
4. Synthesize a label map (periodic) from 2, or take ``output_labels`` drawn by the user.
5. Fill each region with its subtexture.

Section 4, interactions (``fill="cooccurrence"``): subtextures are synthesized one after another
in order of complexity, the entropy of their colour histogram, simplest first. The model of
subtexture n holds its own cliques (head and tail in n) and, for every subtexture m that comes
within ``interaction_distance`` of it in the exemplar, the cliques with head in n and tail in m
and the reverse (ordered: head and tail are told apart). Where m comes earlier, its real
intensities are in the statistics; where it comes later, the value 0 (the mean colour, as PCA
components are centred) stands for it, as it will at synthesis time. Clique types are selected
for each subtexture by the paper's steps 1-7, run in place on the exemplar's own layout (the
exemplar's values in the earlier classes, 0 in the later ones, noise in class n).

Colour: the exemplar's PCA components, each synthesized separately with a common level width
(texsynth.cooccurrence); every subtexture shares the components' quantization so that
differences across a boundary mean the same on both sides.

Any other registered method can fill the regions instead (``fill="heeger_bergen"``, ...): it
gets the largest square of the exemplar inside the class as its exemplar (its own pixels only)
and fills the whole output, which the label map then cuts; no interactions, and a class whose
square is smaller than ``MIN_SQUARE`` (or the method's minimum) is filled with ``cooccurrence``.

Deviations, one line each:
- the label texture is modelled at a reduced scale (``label_scale``, automatic from the mean
  run length of the labels) and upsampled periodically (bilinear class indicators, arg max), so
  that blobs larger than ``max_offset`` stay within reach of the cliques; the upsampling samples
  at smoothly, randomly displaced points, so that boundaries (and the wrap) are not tied to the
  coarse grid;
- the in-place selection runs on a window of the exemplar (at most ``selection_size`` a
  side) where class n is most frequent, treated as a torus;
- the paper's future-work note (simultaneous synthesis of all subtextures) is not attempted;
- an exemplar of more than ``cliques.ANCHORS`` pixels: the subtextures' statistics (colour PCA,
  singletons, own and interaction histograms, which classes meet) come from its sample of
  strips (``cliques.anchor_rows``), the complexity order from a regular sample of its pixels;
  the selection windows are its own pixels;
- production sizes (multiresolution relaxation, as ``texsynth.cooccurrence``): with
  ``fill="cooccurrence"`` and more than ``COARSE_PIXELS`` output pixels, the regions are first
  filled at half size (exemplar, labels and output labels halved), upsampled class by class,
  and relaxed from there for ``REFINE_SWEEPS`` sweeps instead of ``sweeps`` from noise, by
  proposals bounded by each pixel's neighbours (as ``texsynth.cooccurrence``); each
  component's dither keeps the exemplar's correlation within a level
  (``cooccurrence.model.residual_correlation``).

References
----------
Zalesny et al. 2002, sections 1, 3 (segmentation) and 4 (label texture, subtexture
interactions); section 2 for the clique model that fills the regions.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ... import budget, validation
from ...api import synthesize as synthesize_method
from ...blocks.color import ColorPCA
from ...registry import Param, get_method, methods, resolve
from ..cooccurrence import COARSE_PIXELS, REFINE_SWEEPS, upsample_half
from ..cooccurrence import METHOD as CLIQUE_MODEL
from ..cooccurrence import model as co
from ..cooccurrence.cliques import (
    Relaxation,
    Term,
    anchor_rows,
    difference_histograms,
    half_offsets,
    heads,
    pair_values,
    strips,
)
from .segmentation import (
    CONTRAST,
    SAMPLE_PIXELS,
    label_colours,
    labels_from_image,
    segment,
)

__all__ = ["Composite", "compose", "composite", "synthesize_labels", "complexity_order",
           "class_proportion_error", "INTERACTION_DISTANCE", "MIN_SQUARE", "PARAMS"]

INTERACTION_DISTANCE = 2
#: The label texture's share of the progress (:func:`compose`).
LABEL_SHARE = 0.15
#: Smallest inscribed square (pixels a side) handed to another fill method.
MIN_SQUARE = 24
#: Fewest cliques a candidate type needs in the exemplar to be modelled.
MIN_PAIRS = 16
#: Candidate types counted between two progress reports.
CANDIDATE_GROUP = 16
#: Smallest exemplar side: segmentation and a label texture need room.
MIN_EXEMPLAR = 16
#: Upscaled label maps: rms displacement of the sampling points and its correlation length
#: (Gaussian sigma), in coarse pixels; half a pixel spreads boundaries evenly over the fine grid.
SHIFT, SHIFT_LENGTH = 0.5, 2.0

#: The method's parameters (the registered ``composite`` method's; :func:`compose` checks
#: its keyword arguments against them).
PARAMS = (
    Param("fill", str, "cooccurrence", "Method that fills each region (clique model: with "
          "interactions)", choices=("cooccurrence",) + tuple(
              m.name for m in methods() if m.name not in ("composite", "cooccurrence"))),
    Param("interaction_distance", int, INTERACTION_DISTANCE,
          "Reach of the cliques across subtexture boundaries (0: none)", 0, 8),
    Param("max_offset", int, co.MAX_OFFSET, "Longest clique type considered (pixels)", 1, 16),
    Param("threshold", float, co.THRESHOLD,
          "Stop adding clique types when the worst histogram distance is below this",
          0.001, 1.0),
    Param("max_cliques", int, co.MAX_CLIQUES, "Most clique types per subtexture and "
          "colour component", 1, 100),
    Param("levels", int, co.LEVELS, "Grey levels of the strongest colour component", 4, 128),
    Param("sweeps", int, co.SWEEPS, "Relaxation sweeps over the output", 1, 500),
    Param("label_scale", int, 0, "Scale at which the label map is modelled (0: automatic)",
          0, 8),
    Param("contrast", float, CONTRAST, "Segmentation: colour difference (Lab) below which "
          "regions join one class; larger gives fewer classes (0: automatic, the largest "
          "of 6, 3, 2 that finds two classes)", 0.0, 100.0),
    Param("texture_features", bool, False, "Segmentation: add filter-bank texture features "
          "to the colour"),
)


def memory(shape, width, height, params) -> float:
    """Peak bytes: the clique model's working set, the label maps, which (term, end)
    columns each pixel takes part in (2 bytes per typical selected type and pixel) and their
    summed second-order weight (a float64 per pixel); the exemplar's segmentation (features,
    labels and a block index: 32 bytes a pixel) and its sampled labels, marks and counts (16
    bytes a sampled pixel)."""
    t = min(params["max_cliques"], co.TYPICAL_TYPES)
    return (CLIQUE_MODEL.memory(shape, width, height, params) + (24 + 2 * t) * width * height
            + 32 * shape[0] * shape[1] + 16 * co.sampled_pixels(shape, params["max_offset"]))


@dataclass(frozen=True)
class Composite:
    """The output ``image`` (height, width, C), the exemplar's ``labels`` (H, W), the
    ``output_labels`` (height, width), the synthesis ``order`` of the classes and the classes
    filled with ``cooccurrence`` because their square was too small for the chosen method."""

    image: np.ndarray
    labels: np.ndarray
    output_labels: np.ndarray
    order: tuple[int, ...]
    fallbacks: tuple[int, ...] = ()


def complexity_order(exemplar: np.ndarray, labels: np.ndarray, bins: int = 8) -> list[int]:
    """Classes by the entropy of their colour histogram (``bins`` per channel), lowest first;
    from every ``step``-th pixel of an exemplar of more than ``segmentation.SAMPLE_PIXELS``."""
    x = np.asarray(exemplar, np.float32)
    step = -(-labels.size // SAMPLE_PIXELS)
    x, labels = x.reshape(-1, x.shape[2])[::step], np.asarray(labels).ravel()[::step]
    lo, hi = x.min(axis=0), x.max(axis=0)
    q = np.clip(((x - lo) / np.maximum(hi - lo, 1e-6) * bins).astype(np.int64), 0, bins - 1)
    code = np.zeros(labels.shape, np.int64)
    for c in range(x.shape[1]):
        code = code * bins + q[:, c]
    entropy = []
    for k in range(int(labels.max()) + 1):
        p = np.bincount(code[labels == k]).astype(np.float64)
        p = p[p > 0] / max(p.sum(), 1)
        entropy.append(float(-(p * np.log2(p)).sum()))
    return [int(k) for k in np.argsort(entropy, kind="stable")]


def class_proportion_error(labels: np.ndarray, output_labels: np.ndarray) -> float:
    """Half the L1 distance between the class proportions of two label maps (0 = same)."""
    k = int(max(labels.max(), output_labels.max())) + 1
    p = np.bincount(labels.ravel(), minlength=k) / labels.size
    q = np.bincount(output_labels.ravel(), minlength=k) / output_labels.size
    return float(np.abs(p - q).sum() / 2)


# --- the label texture -----------------------------------------------------------------------


def _run_length(labels: np.ndarray) -> float:
    """Mean length of constant runs along rows and columns."""
    h, w = labels.shape
    rows = h * w / (np.count_nonzero(labels[:, 1:] != labels[:, :-1]) + h)
    cols = h * w / (np.count_nonzero(labels[1:] != labels[:-1]) + w)
    return float((rows + cols) / 2)


def _downscale(labels: np.ndarray, f: int, classes: int) -> np.ndarray:
    """Majority label of each f x f block (the smallest label among tied ones)."""
    h, w = (labels.shape[0] // f) * f, (labels.shape[1] // f) * f
    block = (np.arange(h)[:, None] // f) * (w // f) + np.arange(w) // f
    votes = np.bincount((block * classes + labels[:h, :w]).ravel(),
                        minlength=block.size // (f * f) * classes)
    return votes.reshape(h // f, w // f, classes).argmax(axis=2).astype(np.int32)


def _upscale(labels: np.ndarray, height: int, width: int, classes: int,
             rng: np.random.Generator, tick) -> np.ndarray:
    """Periodic bilinear interpolation of each class's indicator, then the arg max, sampled at
    points moved by a smooth random periodic displacement (``SHIFT`` coarse pixels rms, over
    ``SHIFT_LENGTH`` coarse pixels): unshifted, every straight boundary falls between the same
    two fine rows or columns of each coarse pixel, and so does the wrap. ``tick()`` before each
    class (a 2048^2 map takes a second)."""
    h, w = labels.shape
    y = (np.arange(height) + 0.5) * h / height - 0.5
    x = (np.arange(width) + 0.5) * w / width - 0.5
    points = np.stack(np.meshgrid(y, x, indexing="ij"))
    shift = ndimage.gaussian_filter(rng.standard_normal((2, h, w)), (0, SHIFT_LENGTH,
                                                                      SHIFT_LENGTH), mode="wrap")
    shift *= SHIFT / np.maximum(shift.std(axis=(1, 2), keepdims=True), 1e-12)
    points += [ndimage.map_coordinates(d, points, order=1, mode="grid-wrap") for d in shift]
    best = np.full((height, width), -1.0)
    out = np.zeros((height, width), np.int32)
    for k in range(classes):
        tick()
        v = ndimage.map_coordinates((labels == k).astype(np.float64), points, order=1,
                                    mode="grid-wrap")
        better = v > best
        out[better], best[better] = k, v[better]
    return out


def synthesize_labels(labels: np.ndarray, width: int, height: int, *,
                      seed: int | np.random.Generator = 0, label_scale: int = 0,
                      max_offset: int = co.MAX_OFFSET, threshold: float = co.THRESHOLD,
                      max_cliques: int = co.MAX_CLIQUES, sweeps: int = co.SWEEPS,
                      progress: Callable[[float, str], object] | None = None) -> np.ndarray:
    """A periodic label map (height, width) with the label texture of ``labels`` (steps 2, 4).

    ``label_scale``: the label texture is modelled and synthesized ``label_scale`` times smaller
    (0: automatic, the mean run length over ``max_offset``, at most 8, keeping at least 32
    pixels a side).
    """
    rng, report = budget.start(seed, progress)
    classes = int(labels.max()) + 1
    f = label_scale or int(np.clip(round(_run_length(labels) / max_offset), 1, 8))
    f = max(1, min(f, min(labels.shape) // 32 or 1))
    report(0.0, "modelling the label texture")
    small = _downscale(labels, f, classes) if f > 1 else labels
    shape = (-(-height // f), -(-width // f))
    # the fit's share by the clique model's terms (a fixed 0.3 had taken 0.69 of the time,
    # 128 -> 256)
    fitted = co.fit_share(small.shape + (1,), shape[1], shape[0],
                          {"max_offset": max_offset, "max_cliques": max_cliques,
                           "sweeps": sweeps})
    model = co.fit_labels(small, classes, seed=rng, max_offset=max_offset, threshold=threshold,
                          max_cliques=max_cliques, progress=report.span(0.0, fitted))
    marks = co.synthesize_channel(model.channels[0], shape, rng, sweeps,
                                  report.span(fitted, 1.0))
    out = model.channels[0].decode(marks, rng)
    if f == 1:
        return out
    return _upscale(out, height, width, classes, rng,
                    lambda: report(1.0, "upscaling the label map"))


# --- the subtextures --------------------------------------------------------------------------


def _window(mask: np.ndarray, side: int) -> tuple[slice, slice]:
    """The side x side window of the exemplar holding the most pixels of ``mask``."""
    h, w = mask.shape
    sh, sw = min(side, h), min(side, w)
    box = ndimage.uniform_filter(mask.astype(np.float32), (sh, sw), mode="constant")
    oy, ox = sh // 2, sw // 2
    valid = box[oy:h - sh + oy + 1, ox:w - sw + ox + 1]
    y, x = np.unravel_index(int(np.argmax(valid)), valid.shape)
    return slice(y, y + sh), slice(x, x + sw)


def _neighbours(labels: np.ndarray, n: int, distance: int) -> list[int]:
    """Classes with a pixel within ``distance`` (Chebyshev) of a pixel of class n: the other
    ends of the cliques of types up to ``distance`` that have one end in n (``labels``: an
    image, or its sample of strips)."""
    if distance < 1:
        return []
    near = np.zeros(int(labels.max()) + 1, bool)
    for d in half_offsets(distance):
        head, tail = pair_values(labels, d, False)
        near[tail[head == n]] = True
        near[head[tail == n]] = True
    near[n] = False
    return [int(m) for m in np.flatnonzero(near)]


def _own_histograms(marks: np.ndarray, labels: np.ndarray, offsets: np.ndarray, span: int,
                    classes: int, tick=None) -> np.ndarray:
    """Step 1's own cliques of every class at once: counts int64 (types, classes, bins) of the
    cliques of each type with both ends in one class (a class's own cliques see its real
    values whatever the order). ``tick()``, when given, is called before each group of types."""
    bins = 2 * span + 1
    out = np.zeros((len(offsets), classes, bins), np.int64)
    for i, d in enumerate(offsets):
        if tick is not None and i % CANDIDATE_GROUP == 0:
            tick()
        head, tail = pair_values(marks, d, False)
        lh, lt = pair_values(labels, d, False)
        code = np.where(lh == lt, lh * bins + tail - head + span, classes * bins)
        out[i] = np.bincount(code.ravel(), minlength=(classes + 1) * bins)[:classes * bins
                                                                          ].reshape(classes, bins)
    return out


def _candidates(seen: np.ndarray, labels: np.ndarray, n: int, others: list[int], span: int,
                max_offset: int, own: np.ndarray, distance: int,
                tick=None) -> tuple[list[Term], np.ndarray]:
    """Step 1 for class n: its own clique types up to ``max_offset`` (``own``: their counts
    from :func:`_own_histograms`) and its interaction types, with the exemplar's normalised
    histograms and clique counts; types with fewer than ``MIN_PAIRS`` cliques are left out.
    ``tick()``, when given, is called before each group of interaction types."""
    types = half_offsets(max_offset)
    near = half_offsets(distance) if distance >= 1 else np.zeros((0, 2), np.int32)
    spec = [(d, n, n) for d in types]
    for m in others:
        spec += [(d, n, m) for d in near] + [(d, m, n) for d in near]
    counts = [own[:, n]]
    for a in range(len(types), len(spec), CANDIDATE_GROUP):
        if tick is not None:
            tick()
        group = spec[a:a + CANDIDATE_GROUP]
        counts.append(difference_histograms(seen, [s[0] for s in group], span, False, labels,
                                            [(s[1], s[2]) for s in group]))
    counts = np.concatenate(counts)
    total = counts.sum(axis=1)
    keep = total >= MIN_PAIRS
    terms = [Term((int(d[0]), int(d[1])), (c / t).astype(np.float32), a, b)
             for (d, a, b), c, t, k in zip(spec, counts, total, keep, strict=True) if k]
    return terms, total[keep]


def _fill_cooccurrence(x, labels, out_labels, order, rng, report, interaction_distance,
                       max_offset, threshold, max_cliques, levels, sweeps, selection_size,
                       start=None):
    """Section 4: every PCA component, every class in ``order``, with interactions; each
    region relaxed from noise, or from the image ``start`` (the output's size) when given
    (each region's pixels from its own class: :func:`_upsample_by_class`), by steps of one
    level (``cooccurrence.model.synthesize_channel``).
    The exemplar's statistics come from its sample of strips (``cliques.anchor_rows``: every
    pixel up to ``cliques.ANCHORS``), its selection windows from its own pixels."""
    reach = max(max_offset, interaction_distance)
    rows = anchor_rows(labels.shape, reach, rng)
    report(0.0, "exemplar statistics")
    xs, ls = strips(x, rows, reach), strips(labels, rows, reach)
    ls_heads = heads(ls, rows)
    pca = ColorPCA.fit(heads(xs, rows))
    comp = co.principal_components(pca, xs, report)
    report(0.0, "exemplar statistics")
    initial = None if start is None else pca.forward(start)
    report(0.0, "exemplar statistics")
    axes = tuple(range(comp.ndim - 1))
    lo, hi = comp.min(axis=axes), comp.max(axis=axes)
    width = max(float(hi[0] - lo[0]), 1e-6) / levels
    channels = x.shape[2]
    present = [n for n in order if (out_labels == n).any()]
    # per class: its selection window of the exemplar (labels, colour components) and the
    # classes within reach of its interaction cliques
    windows = {}
    for n in present:
        report(0.0, "exemplar statistics")
        wy, wx = _window(labels == n, selection_size)
        windows[n] = labels[wy, wx], pca.forward(x[wy, wx])
    others = {n: _neighbours(ls, n, interaction_distance) for n in present}
    classes = int(labels.max()) + 1
    out = np.zeros(out_labels.shape + (channels,), np.float32)
    grey = [int(np.clip(np.ceil((hi[k] - lo[k]) / width), 2, levels)) for k in range(channels)]
    ends = _fill_shares(grey, [windows[n][0].size for n in present],
                        [int((out_labels == n).sum()) for n in present], sweeps)
    for k in range(channels):
        g = grey[k]
        levels_k = np.arange(g, dtype=np.int32)
        begun = ends[k * len(present), 0] if present else 0.0
        report(begun, "exemplar statistics")
        marks = co.quantize(comp[..., k], lo[k], lo[k] + g * width, g)
        marks_heads = heads(marks, rows)
        zero = int(co.quantize(np.float32(0.0), lo[k], lo[k] + g * width, g))
        synth = np.full(out_labels.shape, zero, np.int32)
        own = _own_histograms(marks, ls, half_offsets(max_offset), g - 1, classes,
                              lambda f=begun: report(f, "exemplar statistics"))
        for i, n in enumerate(present):
            step = k * len(present) + i
            part = report.span(ends[step, 0], ends[step, 2])
            selected = (ends[step, 1] - ends[step, 0]) / (ends[step, 2] - ends[step, 0])
            later = order[order.index(n) + 1:]
            seen = marks.copy()
            seen[np.isin(ls, later)] = zero
            singleton = np.bincount(marks_heads[ls_heads == n], minlength=g).astype(np.float64)
            singleton /= singleton.sum()
            candidates, counts = _candidates(seen, ls, n, others[n], g - 1, max_offset, own,
                                             interaction_distance,
                                             lambda part=part: part(0.0, "exemplar statistics"))
            # steps 2-7 in place, on the window of the exemplar where class n is most frequent
            window, window_comp = windows[n]
            start = co.quantize(window_comp[..., k], lo[k], lo[k] + g * width, g)
            start[np.isin(window, later)] = zero
            free = window == n
            start[free] = levels_k[rng.integers(0, g, int(free.sum()))]
            chosen, _ = co.select(candidates, counts, singleton, levels_k, start, rng,
                                  window, n, threshold, max_cliques, co.SELECTION_SWEEPS,
                                  co.STEP, part.span(0.0, selected))
            # synthesis of class n in the output, earlier classes in place, later ones 0
            region = out_labels == n
            if initial is None:
                synth[region] = rng.choice(levels_k, size=int(region.sum()), p=singleton)
            else:
                synth[region] = co.quantize(initial[:, :, k][region], lo[k],
                                            lo[k] + g * width, g)
            part(selected, "starting the synthesis")
            relax = Relaxation(synth, levels_k, singleton, [candidates[c] for c in chosen],
                               out_labels, n, co.STEP if initial is None else 1,
                               lambda part=part, f=selected: part(f, "counting cliques"),
                               bounded=initial is not None)
            relax.run(sweeps, rng, part.span(selected, 1.0), f"component {k + 1}, class {n}: ")
            synth = relax.image
        values = heads(comp, rows)[..., k]
        centres, spreads = co.level_statistics(values, marks_heads, lo[k], lo[k] + g * width, g)
        out[:, :, k] = co.dither(synth, centres, spreads, rng,
                                 co.residual_correlation(values, marks_heads, centres))
    return np.clip(pca.inverse(out), x.min(axis=(0, 1)), x.max(axis=(0, 1)))


def _fill_shares(grey, windows, regions, sweeps) -> np.ndarray:
    """The progress at the start of each (component, class) step of :func:`_fill_cooccurrence`,
    at the end of its selection and at its end: (steps, 3). A step's work is the clique
    model's (``co.cost``): a selection's sweeps over the class's window per type, the
    relaxation's sweeps per type and one more (``co.synthesis_cost``) over its region and half
    the canvas (its sets are laid over the canvas: a class of a fifth of the output relaxed in
    0.64 of the time of one of four fifths, with 24 types against 15, which the shares cannot
    know beforehand; half fits both at 128 -> 256). A component's types grow with
    its grey levels to the power 1.5 (measured), ``co.TYPICAL_TYPES`` at the first. Shares
    without the types and the canvas had told 90 % done with a quarter of the time left
    (128 -> 256); equal ones, half done at a third of the time."""
    canvas = sum(regions)
    work = []
    for g in grey:
        types = co.TYPICAL_TYPES * (g / max(grey)) ** 1.5
        work += [(types * co.SELECTION_COST * co.SELECTION_SWEEPS * a,
                  (1 + types) * co.SWEEP_COST * sweeps * (b + canvas / 2))
                 for a, b in zip(windows, regions, strict=True)]
    ends = np.cumsum([0.0] + [w for pair in work for w in pair])
    ends /= max(ends[-1], 1e-30)
    return np.stack([ends[0:-1:2], ends[1::2], ends[2::2]], axis=1)


def _fill_coarse_to_fine(x, labels, out_labels, order, rng, report, interaction_distance,
                         max_offset, threshold, max_cliques, levels, sweeps, selection_size):
    """:func:`_fill_cooccurrence`, from a half-size fill (recursively) above ``COARSE_PIXELS``
    output pixels, when halving keeps every class of the exemplar and the output; each
    region starts from its own class's half-size fill (:func:`_upsample_by_class`)."""
    (h, w), (height, width) = x.shape[:2], out_labels.shape
    classes = int(max(labels.max(), out_labels.max())) + 1
    start = None
    if width * height > COARSE_PIXELS and min(h, w) >= 64 and height % 2 == width % 2 == 0:
        report(0.0, "halving the exemplar")
        half_lab, half_out = _downscale(labels, 2, classes), _downscale(out_labels, 2, classes)
        if (np.array_equal(_present(half_lab, classes), _present(labels, classes))
                and np.array_equal(_present(half_out, classes), _present(out_labels, classes))):
            report(0.0, "halving the exemplar")
            half = x[:h // 2 * 2, :w // 2 * 2].reshape(h // 2, 2, w // 2, 2, -1).mean(axis=(1, 3))
            params = {"max_offset": max_offset, "threshold": threshold,
                      "max_cliques": max_cliques, "levels": levels, "sweeps": sweeps}
            coarse_share = CLIQUE_MODEL.cost(half.shape, width // 2, height // 2, params) \
                / CLIQUE_MODEL.cost(x.shape, width, height, params)  # the progress' share
            coarse = _fill_coarse_to_fine(half, half_lab, half_out, order, rng,
                                          report.span(0.0, coarse_share), interaction_distance,
                                          max_offset, threshold, max_cliques, levels, sweeps,
                                          selection_size)
            start = _upsample_by_class(coarse, half_out, out_labels, lambda report=report:
                                       report(coarse_share, "upsampling the half-size fill"))
            sweeps = min(sweeps, REFINE_SWEEPS)
            report = report.span(coarse_share, 1.0)
    return _fill_cooccurrence(x, labels, out_labels, order, rng, report, interaction_distance,
                              max_offset, threshold, max_cliques, levels, sweeps,
                              selection_size, start)


def _upsample_by_class(coarse: np.ndarray, half_labels: np.ndarray, labels: np.ndarray,
                       tick) -> np.ndarray:
    """The half-size fill ``coarse`` (h, w, C) stretched over ``labels``' (height, width)
    (:func:`..cooccurrence.upsample_half`), each class's region from its own class's pixels
    only: before upsampling, every pixel of ``coarse`` of another class in ``half_labels``
    takes the value of its nearest pixel of the class (a pixel of a region near a boundary
    would otherwise start from a blend of both classes, which refining steps of one level do
    not undo). ``tick()`` before each class and channel."""
    height, width = labels.shape
    start = np.empty((height, width, coarse.shape[2]), np.float32)
    for n in np.unique(labels):
        tick()
        outside = half_labels != n
        own = coarse
        if outside.any():
            nearest = ndimage.distance_transform_edt(outside, return_distances=False,
                                                     return_indices=True)
            own = coarse[nearest[0], nearest[1]]
        region = labels == n
        start[region] = upsample_half(own, height, width, tick)[region]
    return start


def _present(labels: np.ndarray, classes: int) -> np.ndarray:
    """Which of the classes occur in ``labels`` (bool (classes,))."""
    return np.bincount(labels.ravel(), minlength=classes) > 0


def _inscribed_square(mask: np.ndarray) -> tuple[slice, slice, int]:
    """The largest axis-aligned square inside ``mask`` (chessboard distance transform)."""
    padded = np.pad(mask, 1)
    dist = ndimage.distance_transform_cdt(padded, metric="chessboard")[1:-1, 1:-1]
    y, x = np.unravel_index(int(np.argmax(dist)), dist.shape)
    r = int(dist[y, x]) - 1
    return slice(y - r, y + r + 1), slice(x - r, x + r + 1), 2 * r + 1


# --- the whole -------------------------------------------------------------------------------


def _as_labels(image, shape, what: str, colours: np.ndarray | None = None,
               classes: int | None = None) -> np.ndarray:
    a = np.asarray(image)
    if a.shape[:2] != tuple(shape):
        raise ValueError(f"the {what} is {a.shape[1] if a.ndim > 1 else '?'} x {a.shape[0]} "
                         f"pixels; it must be {shape[1]} x {shape[0]}")
    if classes is None:
        return labels_from_image(a)
    if a.ndim == 3 and a.shape[2] > 1:
        # a painted colour map: each pixel takes the class of the nearest class colour
        c = a[:, :, :3].astype(np.float64).reshape(-1, 1, min(a.shape[2], 3))
        nearest = ((c - colours[None, :, :c.shape[2]]) ** 2).sum(axis=2).argmin(axis=1)
        return nearest.reshape(shape).astype(np.int32)
    a = a.reshape(shape)
    if a.dtype.kind == "f" and not np.array_equal(a, np.round(a)):
        raise ValueError(f"the {what} must hold whole class numbers or colours")
    if a.min() < 0 or a.max() >= classes:
        raise ValueError(f"the {what} holds classes {int(a.min())}..{int(a.max())}; the "
                         f"exemplar's labels are 0..{classes - 1}")
    return a.astype(np.int32)


def _class_colours(label_image, labels: np.ndarray, classes: int) -> np.ndarray:
    """The colour of each class: mean colour of a painted label image, else the palette."""
    a = np.asarray(label_image) if label_image is not None else None
    if a is None or a.ndim != 3 or a.shape[2] == 1:
        return label_colours(np.arange(classes)[None])[0].astype(np.float64)
    a = a[:, :, :3].astype(np.float64)
    n = np.maximum(np.bincount(labels.ravel(), minlength=classes), 1)
    return np.stack([np.bincount(labels.ravel(), a[:, :, c].ravel(), classes) / n
                     for c in range(a.shape[2])], axis=1)


def compose(exemplar, width: int, height: int, *, labels=None, output_labels=None,
            seed: int = 0, progress: Callable[[float, str], object] | None = None,
            selection_size: int = co.SELECTION_SIZE, fill_params: dict | None = None,
            **params) -> Composite:
    """The composite texture with its label maps: the exemplar's, painted or found, and the
    output's, painted or synthesized (see module notes).

    ``texsynth.synthesize(exemplar, width, height, method="composite", **params)`` gives the
    image of the automatic case; this is the composite's own entry for what a method's
    parameters cannot carry: label images in, the label maps and the classes' order out.

    Parameters
    ----------
    exemplar : array (H, W) or (H, W, C)
        The sample, sRGB-encoded for the automatic segmentation.
    width, height : int
        The output size; a painted ``output_labels`` must have it.
    labels : array (H, W) or (H, W, C), optional
        The exemplar's classes, its size: integer classes, or a painted colour image with one
        flat colour per class. None: unsupervised segmentation (``contrast``,
        ``texture_features``: see :func:`.segmentation.segment`).
    output_labels : array (height, width) or (height, width, C), optional
        The output's layout: integer classes of ``labels``, or colours (each pixel takes the
        class of the nearest class colour: the painted colours of ``labels``, or
        :func:`.segmentation.label_colours`'s palette for automatic labels). None:
        synthesized from the label texture.
    seed : int
        Same inputs and seed give bit-identical output.
    progress : callable(fraction, message), optional
        As for ``texsynth.synthesize``.
    selection_size : int
        Side of the window of the exemplar on which a class's clique types are selected.
    fill_params : dict, optional
        Parameters of the other fill method (``fill`` not ``"cooccurrence"``).
    **params
        The ``composite`` method's parameters (``PARAMS``: ``fill``, ``interaction_distance``,
        ``max_offset``, ...), their defaults when left out.

    Returns
    -------
    Composite
        The image (height, width, C), ``labels``, ``output_labels``, ``order``, ``fallbacks``.

    Raises ``ValueError`` for a label image of the wrong size, a single class, or a fill
    method that does not exist.

    References
    ----------
    Zalesny et al. 2002, sections 3 (segmentation) and 4 (label texture, interactions).

    Examples
    --------
    >>> import numpy as np
    >>> grain = 0.05 * np.random.default_rng(0).random((24, 24, 3), dtype=np.float32)
    >>> photo = grain + np.where(np.arange(24) < 12, 0.2, 0.8).astype(np.float32)[:, None]
    >>> halves = np.repeat((np.arange(24) >= 12)[:, None], 24, axis=1).astype(np.int32)
    >>> result = compose(photo, 24, 16, labels=halves, seed=1, sweeps=1, max_cliques=2)
    >>> result.image.shape, result.output_labels.shape, sorted(result.order)
    ((16, 24, 3), (16, 24), [0, 1])
    """
    if params.get("fill") == "composite":
        raise ValueError("fill must be a single-texture method, not 'composite'")
    checked = resolve(PARAMS, params, "composite.compose")
    x = validation.image(exemplar, min_side=MIN_EXEMPLAR)
    width, height = validation.size(width, height)
    seed = validation.seed(seed)
    selection_size = validation.whole(selection_size, "selection_size", 8, validation.MAX_SIDE)
    if fill_params is not None and not isinstance(fill_params, dict):
        raise ValueError(f"fill_params must be a dict of the fill method's parameters, got "
                         f"{type(fill_params).__name__}")
    what = f"composite synthesis of {width} x {height}"
    budget.admit(what, peak=memory(x.shape, width, height, checked),
                 seconds=cost(x.shape, width, height, checked) * budget.machine_factor())
    rng, report = budget.start(seed, progress)
    return _compose(x, width, height, rng, report, checked, labels, output_labels,
                    selection_size, fill_params)


def composite(exemplar, width, height, rng, progress, fill="cooccurrence",
              interaction_distance=INTERACTION_DISTANCE, max_offset=co.MAX_OFFSET,
              threshold=co.THRESHOLD, max_cliques=co.MAX_CLIQUES, levels=co.LEVELS,
              sweeps=co.SWEEPS, label_scale=0, contrast=CONTRAST, texture_features=False):
    """Segment ``exemplar`` into subtextures, synthesize a label map and fill each region
    (height, width, C) (see the module notes); the registered ``composite`` method.

    Deviation: the work draws from a generator seeded by one draw of ``rng`` (so a seed gives
    the image it gave when this function called :func:`compose`).

    Parameters
    ----------
    exemplar : float32 array (H, W, C)
        The sample, validated by ``texsynth.synthesize``.
    width, height : int
        The output size, larger or smaller than the exemplar.
    rng, progress : numpy.random.Generator, texsynth.progress.Progress
        The seeded generator and the progress reporter ``texsynth.synthesize`` makes.
    fill : str
        Method that fills each region (``cooccurrence``, the clique model, with interactions;
        or another registered method but ``composite``).
    interaction_distance : int
        Reach of the cliques across subtexture boundaries (0: none).
    max_offset : int
        Longest clique type considered (pixels).
    threshold : float
        Stop adding clique types when the worst histogram distance is below this.
    max_cliques : int
        Most clique types per subtexture and colour component.
    levels : int
        Grey levels of the strongest colour component.
    sweeps : int
        Relaxation sweeps over the output.
    label_scale : int
        Scale at which the label map is modelled (0: automatic).
    contrast : float
        Segmentation: colour difference (Lab) below which regions join one class; larger gives
        fewer classes (0: automatic, the largest of 6, 3, 2 that finds two classes).
    texture_features : bool
        Segmentation: add filter-bank texture features to the colour.

    Returns
    -------
    numpy.ndarray
        float32 (height, width, C), periodic.

    References
    ----------
    Zalesny et al. 2002, section 3 (the segmentation), section 4 (the label texture and the
    subtextures' interactions) and section 2 (the clique model that fills them).

    Examples
    --------
    A dark and a light subtexture side by side: the output holds both, in like shares.

    >>> import numpy as np, texsynth
    >>> grain = 0.05 * np.random.default_rng(0).random((24, 24, 3), dtype=np.float32)
    >>> photo = grain + np.where(np.arange(24) < 12, 0.2, 0.8).astype(np.float32)[:, None]
    >>> out = texsynth.synthesize(photo, 24, 24, method="composite", seed=1, sweeps=1,
    ...                           max_cliques=2, max_offset=2)
    >>> out.shape, 0.25 < float((out[..., 0] < 0.5).mean()) < 0.75
    ((24, 24, 3), True)
    """
    params = {"fill": fill, "interaction_distance": interaction_distance,
              "max_offset": max_offset, "threshold": threshold, "max_cliques": max_cliques,
              "levels": levels, "sweeps": sweeps, "label_scale": label_scale,
              "contrast": contrast, "texture_features": texture_features}
    rng = np.random.default_rng(int(rng.integers(2**31)))
    return _compose(exemplar, width, height, rng, progress, params).image


def _compose(x, width, height, rng, report, params, labels=None, output_labels=None,
             selection_size=co.SELECTION_SIZE, fill_params=None) -> Composite:
    """Steps 1-5 on the validated exemplar ``x``, with ``params`` the method's (resolved)."""
    (fill, interaction_distance, max_offset, threshold, max_cliques, levels, sweeps,
     label_scale, contrast, texture_features) = (params[p.name] for p in PARAMS)
    h, w = x.shape[:2]
    # the progress' shares: the segmentation by the cost model, the label texture measured
    # (a fixed 0.18 had taken 0.03-0.13 of the time at 128 -> 256, the brick's 0.15), the
    # fill the rest
    segmented = 3.5e-7 * h * w / cost(x.shape, width, height, params)
    labelled = segmented + LABEL_SHARE
    if labels is None:
        report(0.0, "segmenting the exemplar")
        lab = segment(x, contrast=contrast, texture=texture_features, seed=rng,
                      tick=lambda: report(0.0, "segmenting the exemplar"))
        report(segmented, "modelling the label texture")
    else:
        lab = _as_labels(labels, (h, w), "label image")
    classes = int(lab.max()) + 1
    if classes < 2:
        raise ValueError("the exemplar has a single class: nothing to compose; use a "
                         "single-texture method such as 'cooccurrence', or paint labels"
                         + ("" if labels is not None else " (or lower the contrast)"))
    if output_labels is None:
        out_lab = synthesize_labels(lab, width, height, seed=rng, label_scale=label_scale,
                                    max_offset=max_offset, threshold=threshold,
                                    max_cliques=max_cliques, sweeps=sweeps,
                                    progress=report.span(segmented, labelled))
    else:
        out_lab = _as_labels(output_labels, (height, width), "output label map",
                             _class_colours(labels, lab, classes), classes)
    order = complexity_order(x, lab)
    fill_part = report.span(labelled, 1.0)
    fallbacks = []
    if fill == "cooccurrence":
        image = _fill_coarse_to_fine(x, lab, out_lab, order, rng, fill_part,
                                     interaction_distance, max_offset, threshold, max_cliques,
                                     levels, sweeps, selection_size)
    else:
        method = get_method(fill)
        image = np.zeros((height, width, x.shape[2]), np.float32)
        todo = [n for n in order if (out_lab == n).any()]
        for i, n in enumerate(todo):
            part = fill_part.span(i / len(todo), (i + 1) / len(todo))
            sy, sx, side = _inscribed_square(lab == n)
            region = out_lab == n
            if side >= max(MIN_SQUARE, method.min_exemplar):
                sub = synthesize_method(x[sy, sx], width, height, fill,
                                        int(rng.integers(2**31)), part, **(fill_params or {}))
            else:
                fallbacks.append(n)
                only = np.where(lab == n, n, (n + 1) % classes)
                sub = _fill_cooccurrence(x, only, np.full((height, width), n, np.int32), [n],
                                         rng, part, 0, max_offset, threshold, max_cliques,
                                         levels, sweeps, selection_size)
            image[region] = sub[region]
    return Composite(np.ascontiguousarray(image, np.float32), lab, out_lab, tuple(order),
                     tuple(fallbacks))


def cost(shape, width, height, params):
    """Segmentation (3.5e-7 s a pixel of the exemplar), then a clique model per class (each
    over its share of the output, with interactions) and the label texture: measured 1.9
    single clique models (wall time, 2048 x 2048 from the 12 MP setts photo and from a 1024
    crop of it), both relaxed from a half-size start above COARSE_PIXELS. Refitted (issue 45)
    on 64 -> 128, 64 -> 1024 x 32 and 32 -> 256 (quiet: 2.7, 3.8, 5.5 s, the single-model
    scale had told 1.6, 1.0 and 0.6 of them): 2.4 single models, less 1.9 of the exemplar's
    type selection (each class selects on its own pixels, not the exemplar's), and the
    classes' set-up, 4.4 s more. Then all scaled by 1.2 (issue 45: the three rows read
    0.91-0.95 of the predictions table's median seconds over cost on one host, 1.28-1.41 on the
    next: the relaxation's many small numpy calls, slower there than the calibration's FFTs).
    Then all scaled by 0.855, when the clique model's own cost was refitted (its statistics
    and sweeps), so that these three rows are told what they were (within 6 %); the 2048^2
    runs from the setts are told 1.18-1.23x more, as the clique model's are."""
    return 5.0 + 3.6e-7 * shape[0] * shape[1] + 2.5 * CLIQUE_MODEL.cost(
        shape, width, height, params) - 2.0 * co.selection_cost(shape, params)
