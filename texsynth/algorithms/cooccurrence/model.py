"""The pairwise clique model: clique-type selection, synthesis from a model, a small model file.

Zalesny et al. 2002, section 2, steps 1-7, after
their reference [13]. A model is a neighbourhood system (the selected clique types) plus, for
each selected type, the histogram of intensity differences of its pixel pairs, plus the
singleton (intensity) histogram. Once fitted, the exemplar is no longer needed::

    model = texsynth.cooccurrence.fit(exemplar)
    model.save("marble.npz")                      # a few KB
    image = Model.load("marble.npz").synthesize(1024, 1024, seed=1)

Selection (:func:`select`), as in the paper:
    1. the difference histograms of every clique type up to ``max_offset`` in the exemplar;
    2. a working image of independent noise, uniform over the exemplar's levels;
    3. the same histograms in the working image;
    4. the Euclidean distance of each type's histogram to the exemplar's;
    5. the worst type: if its distance is below ``threshold`` stop, else add it to the model;
    6. synthesize the working image with the enlarged model (:class:`.cliques.Relaxation`);
    7. go to 3.

Colour: each PCA component of the exemplar (texsynth.blocks.color.ColorPCA) gets its own model,
selected and synthesized independently. Why not colour clique statistics: a joint histogram of
colour differences has G^3 bins per clique type, hundreds of KB where the paper reports a few
hundred to a few thousand bytes; along the principal axes the channels are uncorrelated at
offset zero, which is what independent synthesis needs (their cross-correlation at other offsets
is lost: the price of the small model).

Deviations, one line each:
- intensities are quantized: ``levels`` grey levels for the first PCA component and levels of
  the same width for the others (fewer); a level decodes to the mean of the exemplar's values
  in it plus uniform dither of their spread (:func:`level_statistics`), not to the level's
  middle plus a level's width: the values in a level are not spread evenly over it (on the
  setts photo the middle is up to 0.37 of a level off their mean), and a weak component that
  fits in one level got noise of a level's width, 1.7 times its own spread (colour speckle);
- that dither is not white: it has the exemplar's lag-one correlation within a level
  (:func:`residual_correlation`, :func:`dither`; about 0.1 for the first component, whose
  within-level variation is pixel noise, 0.4-0.9 for the weak ones, which vary smoothly
  within their few levels): white, it made the weak components' mean gradient 2.8-3.5 times
  the photo's (a fine colour grain, yellow and pink specks on the setts photo), now 1.1-2.1;
- the singleton histogram is always in the model (the paper lets step 5 select it like a type);
- step 6 continues from the previous working image (warm start) for ``selection_sweeps``
  sweeps instead of restarting from noise;
- selection synthesizes on a torus of at most ``selection_size`` pixels a side; the exemplar's
  histograms use only pairs inside the photograph (no wrap-around pairs);
- an exemplar of more than ``cliques.ANCHORS`` pixels is analysed on a sample
  (``cliques.anchor_rows``): its colour PCA, ranges, singleton and clique histograms come from
  ``ANCHORS`` heads on randomly drawn rows of the whole photograph, not from every pixel;
- histograms are stored as float16 (the file is the model; reloading gives the same numbers,
  and the same output at the same seed, bit for bit);
- ``sweeps`` is a most: synthesis ends after a sweep that changes fewer than
  ``cliques.CONVERGED`` of the pixels (a label map converges in about 12 of 30, measured).
"""

from __future__ import annotations

import io
import json
import zipfile
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy import ndimage, special

from ... import budget, validation
from ...blocks.color import ColorPCA
from ...blocks.parallel import serial_blas
from ...progress import Progress
from ...registry import Param, resolve
from .cliques import (
    ANCHORS,
    GOLOMB,
    PairIndex,
    Relaxation,
    Term,
    anchor_rows,
    difference_histograms,
    half_offsets,
    heads,
    strips,
)

__all__ = ["ChannelModel", "Model", "fit", "fit_channel", "relax", "select", "quantize",
           "label_levels", "level_statistics", "residual_correlation", "dither",
           "principal_components", "FORMAT", "PARAMS"]

FORMAT = "texsynth-cooccurrence-1"
MAX_OFFSET = 8
THRESHOLD = 0.03
MAX_CLIQUES = 40
LEVELS = 32
SWEEPS = 30
SELECTION_SIZE = 64
SELECTION_SWEEPS = 6
#: A level's dither is white below this lag-one correlation (:func:`dither`).
WHITE = 0.05
#: The most lag-one correlation a dither is given (a Gaussian of sigma 2.2).
MAX_CORRELATION = 0.95
#: Half-width (in levels) of the local proposals for grey levels.
STEP = 3
#: Clique types counted in the exemplar between two progress reports.
TYPE_GROUP = 16
#: Rows (or strips) of the exemplar turned into colour components between two progress reports.
ROWS = 64

#: The method's parameters (the registered ``cooccurrence`` method's, checked by :func:`fit`
#: and :meth:`Model.synthesize` too).
PARAMS = (
    Param("max_offset", int, MAX_OFFSET, "Longest clique type considered (pixels)", 1, 16),
    Param("threshold", float, THRESHOLD,
          "Stop adding clique types when the worst histogram distance is below this",
          0.001, 1.0),
    Param("max_cliques", int, MAX_CLIQUES, "Most clique types per colour component", 1, 100),
    Param("levels", int, LEVELS, "Grey levels of the strongest colour component", 4, 128),
    Param("sweeps", int, SWEEPS, "Relaxation sweeps over the output", 1, 500),
)
#: Bytes a synthesis needs per output pixel and selected clique type (see ``_memory`` in
#: ``__init__``): checked before :meth:`Model.synthesize` allocates.
BYTES_PER_PIXEL = 4 * 6 + 3 * 4 * 4
BYTES_PER_PIXEL_AND_TYPE = 8


def label_levels(classes: int) -> np.ndarray:
    """Marks of ``classes`` labels: a Golomb ruler, so each label pair has its own difference."""
    if not 1 <= classes < len(GOLOMB):
        raise ValueError(f"a label map may have 1 to {len(GOLOMB) - 1} classes, got {classes}")
    return np.array(GOLOMB[classes], np.int32)


def quantize(values: np.ndarray, lo: float, hi: float, levels: int) -> np.ndarray:
    """Level 0..levels-1 of each value on [lo, hi] (equal-width levels)."""
    scale = levels / max(hi - lo, 1e-12)
    return np.clip(np.floor((values - lo) * scale), 0, levels - 1).astype(np.int32)


@dataclass(frozen=True, eq=False)
class ChannelModel:
    """The clique model of one channel (a PCA component, or a label map).

    ``levels``: the marks a pixel takes (0..G-1 for grey levels, a Golomb ruler for labels);
    level i of a grey level decodes to ``centres[i] + (U - 1/2) spreads[i]`` (U uniform on
    [0, 1)): the mean of the exemplar's values in that level and the width of the uniform
    distribution with their standard deviation (:func:`level_statistics`; a model without them
    takes the level's middle, ``lo + (i + 1/2) (hi - lo) / G``, and its width); label i for
    labels.
    ``correlation``: the lag-one correlation of the exemplar's values about their level's
    centre along its rows, which the dither keeps (:func:`residual_correlation`; 0, white
    dither, for a model without it).
    ``offsets`` (n, 2) are the selected clique types in the order they were added, with their
    difference histograms ``histograms`` (n, 2 * span + 1) and the distance each had when it
    was added (``distances``); ``singleton`` is the histogram of the levels.
    """

    lo: float
    hi: float
    levels: np.ndarray
    singleton: np.ndarray
    offsets: np.ndarray
    histograms: np.ndarray
    distances: np.ndarray
    categorical: bool = False
    centres: np.ndarray | None = None
    spreads: np.ndarray | None = None
    correlation: float = 0.0

    @property
    def span(self) -> int:
        return int(self.levels.max())

    def terms(self) -> list[Term]:
        return [Term((int(d[0]), int(d[1])), _normalised(h))
                for d, h in zip(self.offsets, self.histograms, strict=True)]

    def decode(self, marks: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        level = np.searchsorted(self.levels, marks)
        if self.categorical:
            return level.astype(np.int32)
        centres, spreads = _or_middles(self)
        return dither(level, np.asarray(centres, np.float32), np.asarray(spreads, np.float32),
                      rng, self.correlation)

    @staticmethod
    def pack(channels) -> dict:
        """The channels' arrays concatenated (one npz entry each, for a small file)."""
        return {
            "ranges": np.array([[c.lo, c.hi] for c in channels], np.float64),
            "counts": np.array([[len(c.levels), len(c.offsets), c.categorical]
                                for c in channels], np.int32),
            "levels": np.concatenate([c.levels for c in channels]).astype(np.int32),
            "singletons": np.concatenate([c.singleton for c in channels]).astype(np.float16),
            "offsets": np.concatenate([c.offsets for c in channels]).astype(np.int8),
            "histograms": np.concatenate([c.histograms.ravel() for c in channels]
                                         ).astype(np.float16),
            "distances": np.concatenate([c.distances for c in channels]).astype(np.float32),
            "centres": np.concatenate([_or_middles(c)[0] for c in channels]).astype(np.float32),
            "spreads": np.concatenate([_or_middles(c)[1] for c in channels]).astype(np.float32),
            # float64, as the model holds it: float32 had moved a reloaded model's output by 6e-8
            "correlations": np.array([c.correlation for c in channels], np.float64),
        }

    @classmethod
    def unpack(cls, data) -> tuple[ChannelModel, ...]:
        out, at_level, at_type, at_value = [], 0, 0, 0
        # a file written before the levels' statistics were kept decodes to the levels' middles
        kept = "centres" in data
        # and one written before their correlation was kept, to white dither
        correlations = data["correlations"] if "correlations" in data else np.zeros(
            len(data["counts"]), np.float32)
        for (lo, hi), (g, n, categorical), rho in zip(data["ranges"], data["counts"],
                                                      correlations, strict=True):
            levels = data["levels"][at_level:at_level + g]
            bins = 2 * int(levels.max()) + 1
            at = slice(at_level, at_level + g)
            out.append(cls(float(lo), float(hi), levels, data["singletons"][at],
                           data["offsets"][at_type:at_type + n].astype(np.int32),
                           data["histograms"][at_value:at_value + n * bins].reshape(n, bins),
                           data["distances"][at_type:at_type + n], bool(categorical),
                           data["centres"][at] if kept and not categorical else None,
                           data["spreads"][at] if kept and not categorical else None,
                           float(rho)))
            at_level, at_type, at_value = at_level + g, at_type + n, at_value + n * bins
        return tuple(out)


def _or_middles(channel: ChannelModel) -> tuple[np.ndarray, np.ndarray]:
    """A channel's level centres and spreads, or its levels' middles and widths without them."""
    g = len(channel.levels)
    width = (channel.hi - channel.lo) / g
    if channel.centres is None:
        return channel.lo + (np.arange(g) + 0.5) * width, np.full(g, width)
    return np.asarray(channel.centres), np.asarray(channel.spreads)


def level_statistics(values: np.ndarray, level: np.ndarray, lo: float, hi: float,
                     g: int) -> tuple[np.ndarray, np.ndarray]:
    """The mean of the ``values`` that fall in each of the ``g`` levels (``level``: their levels
    0..g-1 on [lo, hi]) and the width of the uniform distribution with their standard deviation
    (sqrt(12) times it): float32 (g,) each; a level no value falls in keeps its middle and
    width.

    Examples
    --------
    >>> values = np.array([0.1, 0.12, 0.14, 0.9], np.float32)
    >>> centres, spreads = level_statistics(values, quantize(values, 0.0, 1.0, 2), 0.0, 1.0, 2)
    >>> [round(float(c), 2) for c in centres], [round(float(s), 3) for s in spreads]
    ([0.12, 0.9], [0.057, 0.0])
    """
    v, i = np.asarray(values, np.float64).ravel(), np.asarray(level).ravel()
    n = np.bincount(i, minlength=g).astype(np.float64)
    width = (hi - lo) / g
    mean = np.bincount(i, v, g) / np.maximum(n, 1)
    var = np.maximum(np.bincount(i, v * v, g) / np.maximum(n, 1) - mean ** 2, 0.0)
    centres = np.where(n > 0, mean, lo + (np.arange(g) + 0.5) * width)
    spreads = np.where(n > 0, np.sqrt(12.0 * var), width)
    return centres.astype(np.float32), spreads.astype(np.float32)


def residual_correlation(values: np.ndarray, level: np.ndarray,
                         centres: np.ndarray) -> float:
    """The lag-one correlation along rows of the ``values`` (R, W) about their levels'
    ``centres``, over the pairs of neighbours in the same level (``level`` (R, W) their levels;
    rows of an image, or of its sample), clipped to [0, ``MAX_CORRELATION``]: how smoothly the
    values vary within a level (a pair across a level's border jumps by its sawtooth, which
    the levels themselves already make).

    Examples
    --------
    >>> ramp = np.tile(np.linspace(0.0, 1.0, 64, dtype=np.float32), (4, 1))
    >>> level = quantize(ramp, 0.0, 1.0, 4)
    >>> centres, _ = level_statistics(ramp, level, 0.0, 1.0, 4)
    >>> bool(residual_correlation(ramp, level, centres) > 0.5)
    True
    >>> noise = np.random.default_rng(0).random((64, 64)).astype(np.float32)
    >>> level = quantize(noise, 0.0, 1.0, 4)
    >>> centres, _ = level_statistics(noise, level, 0.0, 1.0, 4)
    >>> bool(residual_correlation(noise, level, centres) < 0.05)
    True
    """
    level = np.asarray(level)
    r = np.asarray(values, np.float64) - np.asarray(centres, np.float64)[level]
    same = level[..., 1:] == level[..., :-1]
    head, tail = r[..., :-1][same], r[..., 1:][same]
    energy = float((head * head + tail * tail).sum()) / 2
    if energy <= 0.0:
        return 0.0
    return float(np.clip((head * tail).sum() / energy, 0.0, MAX_CORRELATION))


def dither(level: np.ndarray, centres: np.ndarray, spreads: np.ndarray,
           rng: np.random.Generator, correlation: float = 0.0) -> np.ndarray:
    """Values of the levels ``level``: each level's centre plus uniform dither over its
    spread (float32, ``level``'s shape). With ``correlation`` rho, a 2-D ``level`` gets dither
    with that lag-one correlation, periodic: white Gaussian noise smoothed on the torus by a
    Gaussian of sigma = 1 / (2 sqrt(-ln rho)) (the correlation of the result at one pixel is
    exp(-1 / (4 sigma^2))), mapped to uniform by its normal distribution function; below
    ``WHITE`` it is white.

    References
    ----------
    Zalesny et al. 2002, section 2: the model's grey levels; their decoding to values is ours
    (see the module's deviations).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> centres, spreads = np.float32([0.12, 0.9]), np.float32([0.06, 0.0])
    >>> v = dither(np.array([0, 0, 1]), centres, spreads, rng)
    >>> bool(np.all(np.abs(v[:2] - 0.12) <= 0.03)), float(v[2])
    (True, 0.8999999761581421)
    >>> v = dither(np.zeros((64, 64), int), centres, spreads, rng, correlation=0.6)
    >>> bool(np.all(np.abs(v - 0.12) <= 0.03))
    True
    """
    if correlation < WHITE or level.ndim != 2:
        u = rng.random(level.shape, dtype=np.float32) - np.float32(0.5)
    else:
        sigma = 0.5 / np.sqrt(-np.log(correlation))
        field = ndimage.gaussian_filter(rng.standard_normal(level.shape, dtype=np.float32),
                                        sigma, mode="wrap")
        u = (special.ndtr(field / max(float(field.std()), 1e-12)) - 0.5).astype(np.float32)
    return centres[level] + u * spreads[level]


def _normalised(h) -> np.ndarray:
    h = np.asarray(h, np.float64)
    return (h / max(h.sum(), 1e-12)).astype(np.float32)


@dataclass(frozen=True, eq=False)
class Model:
    """A fitted clique model: one :class:`ChannelModel` per PCA component (or one label map).

    ``mean``/``basis`` are the PCA of the exemplar's colours (identity for a label map) and
    ``low``/``high`` its per-channel range, which the synthesized image is clipped to.
    """

    mean: np.ndarray
    basis: np.ndarray
    low: np.ndarray
    high: np.ndarray
    channels: tuple[ChannelModel, ...]
    info: dict = field(default_factory=dict)

    @property
    def cliques(self) -> int:
        """Selected clique types over all channels."""
        return sum(len(c.offsets) for c in self.channels)

    def save(self, path) -> int:
        """Write the model to ``path`` (compressed npz); returns the file's size in bytes."""
        data = self.to_bytes()
        Path(path).write_bytes(data)
        return len(data)

    def to_bytes(self) -> bytes:
        arrays = {"mean": self.mean, "basis": self.basis, "low": self.low, "high": self.high,
                  **ChannelModel.pack(self.channels)}
        header = {"format": FORMAT, "info": self.info}
        arrays["header"] = np.frombuffer(json.dumps(header).encode(), np.uint8)
        buffer = io.BytesIO()
        np.savez_compressed(buffer, **arrays)
        return buffer.getvalue()

    @classmethod
    def load(cls, path) -> Model:
        """Read a model written by :meth:`save`; ``ValueError`` if it is not one, or if it is
        damaged (truncated, corrupt, inconsistent or non-finite arrays, empty histograms)."""
        try:
            with np.load(path, allow_pickle=False) as data:
                header = json.loads(bytes(data["header"]).decode())
                if not isinstance(header, dict) or header.get("format") != FORMAT:
                    found = header.get("format") if isinstance(header, dict) else header
                    raise KeyError(f"format {found!r}, expected {FORMAT!r}")
                model = cls(data["mean"], data["basis"], data["low"], data["high"],
                            ChannelModel.unpack(data), header.get("info", {}))
            model.check()
            return model
        except (OSError, KeyError, EOFError, ValueError, TypeError, IndexError, AttributeError,
                UnicodeDecodeError, zipfile.BadZipFile, zlib.error) as e:
            raise ValueError(f"{path}: not a texsynth clique model, or a damaged one ({e}); "
                             "fit and save the model again") from None

    def check(self) -> None:
        """``ValueError`` unless the arrays fit together and are finite, and every histogram
        has mass (a model read from a file is checked before it is used)."""
        c = len(self.channels)
        arrays = (self.mean, self.basis, self.low, self.high)
        if c == 0 or any(np.asarray(a).size == 0 for a in arrays):
            raise ValueError("empty model")
        if np.asarray(self.basis).shape != (len(self.mean), c) or len(self.low) != len(self.mean) \
                or len(self.high) != len(self.mean):
            raise ValueError("the colour basis does not match the channels")
        for k, ch in enumerate(self.channels):
            levels = np.asarray(ch.levels)
            bins = 2 * int(levels.max(initial=0)) + 1
            if len(levels) < 1 or levels.min() < 0 or np.any(np.diff(levels) <= 0) \
                    or len(ch.singleton) != len(levels):
                raise ValueError(f"channel {k}: levels are not increasing marks")
            if np.asarray(ch.offsets).shape != (len(ch.histograms), 2) \
                    or np.abs(ch.offsets).max(initial=0) > 127 \
                    or np.asarray(ch.histograms).shape[1:] != (bins,):
                raise ValueError(f"channel {k}: clique types and histograms do not match")
            values = [np.asarray(v, np.float64) for v in (ch.singleton, ch.histograms)]
            if not all(np.isfinite(v).all() and (v >= 0).all() for v in values) \
                    or not np.isfinite([ch.lo, ch.hi]).all() \
                    or not 0.0 <= ch.correlation <= MAX_CORRELATION:
                raise ValueError(f"channel {k}: histograms hold negative or non-finite values")
            if values[0].sum() <= 0 or (len(values[1]) and (values[1].sum(axis=1) <= 0).any()):
                raise ValueError(f"channel {k}: a histogram is all zero")
        if not all(np.isfinite(np.asarray(a, np.float64)).all() for a in arrays):
            raise ValueError("the colour transform holds non-finite values")

    def synthesize(self, width: int, height: int, *, seed: int | np.random.Generator = 0,
                   sweeps: int = SWEEPS, progress: Callable[[float, str], object] | None = None
                   ) -> np.ndarray:
        """A periodic (height, width, C) float32 image from this model alone, any size (a
        label-map model: int32 (height, width) labels): :func:`relax`, after the checks.

        ``sweeps``: the most relaxation sweeps; memory and time are checked against the
        budgets before any work.
        """
        width, height = validation.size(width, height)
        sweeps = resolve(PARAMS, {"sweeps": sweeps}, "Model.synthesize")["sweeps"]
        types = max(len(c.offsets) for c in self.channels)
        budget.admit(f"clique model synthesis of {width} x {height}",
                     peak=width * height * (BYTES_PER_PIXEL + BYTES_PER_PIXEL_AND_TYPE * 2
                                            * types),
                     seconds=synthesis_cost(len(self.channels), types, width, height, sweeps)
                     * budget.machine_factor())
        rng, report = budget.start(seed, progress)
        return relax(self, width, height, rng, report, sweeps)


def select(candidates: list[Term], exemplar_pairs: np.ndarray, singleton: np.ndarray,
           levels: np.ndarray, start: np.ndarray, rng: np.random.Generator,
           labels: np.ndarray | None = None, free_class: int = 0,
           threshold: float = THRESHOLD, max_cliques: int = MAX_CLIQUES,
           sweeps: int = SELECTION_SWEEPS, step: int = STEP,
           progress: Progress | None = None) -> tuple[list[int], list[float]]:
    """Steps 3-7 from the working image ``start`` (step 2's noise in its free pixels).

    ``candidates``: every clique term with the exemplar's normalised histogram (step 1), made
    of ``exemplar_pairs`` cliques each. ``labels``/``free_class``: only that class's pixels are
    synthesized (section 4); the others keep their values in ``start``. Returns the indices of
    the selected candidates in the order they were added and the distance each had then.

    Step 5 compares a type's distance with ``threshold`` or, if larger, with 1.5 times the
    distance that sampling alone gives two histograms of that many cliques,
    sqrt((1 - sum p^2)(1/N_exemplar + 1/N_working)): a small subtexture's histograms are noisy.
    """
    progress = progress or Progress()
    span = int(levels.max())
    pairs = PairIndex(start.shape, [t.offset for t in candidates], span, labels,
                      [(t.head, t.tail) for t in candidates])
    # (n, bins) even for n = 0 (a composite class too small for any clique type)
    target = np.array([t.target for t in candidates], np.float64).reshape(len(candidates),
                                                                           2 * span + 1)
    spread = 1.0 - (target ** 2).sum(axis=1)
    image = start
    selected: list[int] = []
    added: list[float] = []
    while True:
        h = pairs.histograms(image)  # step 3
        n = h.sum(axis=1)
        dist = np.sqrt(((h / np.maximum(n, 1)[:, None] - target) ** 2).sum(axis=1))  # step 4
        noise = 1.5 * np.sqrt(spread * (1.0 / np.maximum(exemplar_pairs, 1)
                                        + 1.0 / np.maximum(n, 1)))
        eligible = (n > 0) & (dist >= np.maximum(threshold, noise))
        eligible[selected] = False
        if not eligible.any() or len(selected) >= max_cliques:  # step 5
            return selected, added
        worst = int(np.argmax(np.where(eligible, dist, -np.inf)))
        selected.append(worst)
        added.append(float(dist[worst]))
        relax = Relaxation(image, levels, singleton, [candidates[i] for i in selected], labels,
                           free_class, step)  # step 6
        for _ in range(sweeps):
            relax.sweep(rng)
        image = relax.image
        # the selection typically ends near TYPICAL_TYPES, not at max_cliques (the cost
        # model's count): a share of max_cliques had told a third done, then jumped to the end
        n = len(selected)
        progress(n / max(min(max_cliques, TYPICAL_TYPES), n + 1),
                 f"{n} clique types, worst distance {dist[worst]:.3f}")


def reach(max_offset: int, shape) -> int:
    """The longest clique type an exemplar of ``shape`` (H, W, ...) is fitted with: at most
    ``max_offset``, and short of half its smaller side."""
    return min(max_offset, max(1, min(shape[:2]) // 2 - 1))


def exemplar_histograms(marks: np.ndarray, offsets: np.ndarray, span: int,
                        progress: Progress) -> np.ndarray:
    """Step 1: :func:`.cliques.difference_histograms` of ``marks`` (an image or its sample of
    strips), ``TYPE_GROUP`` types between two progress reports."""
    counts = []
    for a in range(0, len(offsets), TYPE_GROUP):
        progress(0.0, "exemplar statistics")
        counts.append(difference_histograms(marks, offsets[a:a + TYPE_GROUP], span, False))
    return np.concatenate(counts)


def fit_channel(marks: np.ndarray, levels: np.ndarray, lo: float, hi: float,
                rng: np.random.Generator, max_offset: int = MAX_OFFSET,
                threshold: float = THRESHOLD, max_cliques: int = MAX_CLIQUES,
                selection_size: int = SELECTION_SIZE, selection_sweeps: int = SELECTION_SWEEPS,
                categorical: bool = False, progress: Progress | None = None) -> ChannelModel:
    """The clique model of one channel of marks taking values in ``levels``: an image (H, W),
    or the sample of strips of a large one (``cliques.strips``, reaching ``max_offset``, which
    is then taken as it is: :func:`reach` bounds it for a whole image)."""
    progress = progress or Progress()
    span = int(levels.max())
    anchors = marks[:, 0] if marks.ndim == 3 else marks  # cliques.heads
    if marks.ndim == 2:
        max_offset = reach(max_offset, marks.shape)
    offsets = half_offsets(max_offset)
    counts = exemplar_histograms(marks, offsets, span, progress)
    target = counts / np.maximum(counts.sum(axis=1, keepdims=True), 1)
    index = np.full(span + 1, -1, np.int64)
    index[levels] = np.arange(len(levels))
    singleton = np.bincount(index[anchors.ravel()], minlength=len(levels)).astype(np.float64)
    singleton /= singleton.sum()
    shape = tuple(min(s, selection_size) for s in anchors.shape)
    start = levels[rng.integers(0, len(levels), shape)]  # step 2
    candidates = [Term((int(d[0]), int(d[1])), t) for d, t in zip(offsets, target, strict=True)]
    chosen, added = select(candidates, counts.sum(axis=1), singleton, levels, start, rng, None,
                           0, threshold,
                           max_cliques, selection_sweeps, 0 if categorical else STEP, progress)
    return ChannelModel(float(lo), float(hi), levels.astype(np.int32),
                        singleton.astype(np.float16), offsets[chosen].reshape(-1, 2),
                        target[chosen].astype(np.float16).reshape(len(chosen), 2 * span + 1),
                        np.array(added, np.float32), categorical)


def principal_components(pca: ColorPCA, sample: np.ndarray, progress: Progress) -> np.ndarray:
    """``pca.forward(sample)`` (an image or its sample of strips), ``ROWS`` rows or strips at a
    time with a progress report before each (a sample of a large photo holds millions)."""
    out = np.empty(sample.shape[:-1] + (pca.basis.shape[1],), np.float32)
    for a in range(0, len(sample), ROWS):
        progress(0.0, "colour statistics")
        out[a:a + ROWS] = pca.forward(sample[a:a + ROWS])
    return out


@serial_blas()
def fit(exemplar, *, max_offset: int = MAX_OFFSET, threshold: float = THRESHOLD,
        max_cliques: int = MAX_CLIQUES, levels: int = LEVELS,
        selection_size: int = SELECTION_SIZE, selection_sweeps: int = SELECTION_SWEEPS,
        seed: int | np.random.Generator = 0,
        progress: Callable[[float, str], object] | None = None) -> Model:
    """Fit the clique model of ``exemplar`` ((H, W) or (H, W, C) image): section 2, steps 1-7.

    ``max_offset``: longest clique type (Chebyshev, pixels); ``threshold``: step 5's stopping
    distance; ``max_cliques``: most types per channel; ``levels``: grey levels per component.
    """
    x = validation.image(exemplar)
    checked = resolve(PARAMS, {"max_offset": max_offset, "threshold": threshold,
                               "max_cliques": max_cliques, "levels": levels}, "cooccurrence.fit")
    max_offset, threshold = checked["max_offset"], checked["threshold"]
    max_cliques, levels = checked["max_cliques"], checked["levels"]
    selection_size = validation.whole(selection_size, "selection_size", 8, validation.MAX_SIDE)
    selection_sweeps = validation.whole(selection_sweeps, "selection_sweeps", 1, 1000)
    rng, report = budget.start(seed, progress)
    m = reach(max_offset, x.shape)
    report(0.0, "colour statistics")
    rows = anchor_rows(x.shape, m, rng)
    sample = strips(x, rows, m)
    pca = ColorPCA.fit(heads(sample, rows))
    components = principal_components(pca, sample, report)
    channels = []
    c = x.shape[2]
    axes = tuple(range(components.ndim - 1))
    report(0.0, "colour statistics")
    lo, hi = components.min(axis=axes), components.max(axis=axes)
    width = max(float(hi[0] - lo[0]), 1e-6) / levels
    # one level width for every component: a weak component gets few levels, not noise
    grey = [int(np.clip(np.ceil((hi[k] - lo[k]) / width), 2, levels)) for k in range(c)]
    ends = np.cumsum([0.0] + [g ** 1.5 for g in grey])   # the progress' shares (measured: a
    ends /= ends[-1]                                    # component of 2 levels fits at once)
    for k in range(c):
        g = grey[k]
        report(ends[k], "exemplar statistics")
        marks = quantize(components[..., k], lo[k], lo[k] + g * width, g)
        channel = fit_channel(marks, np.arange(g, dtype=np.int32), lo[k], lo[k] + g * width,
                              rng, m, threshold, max_cliques, selection_size, selection_sweeps,
                              progress=report.span(ends[k], ends[k + 1]))
        values, level = heads(components, rows)[..., k], heads(marks, rows)
        centres, spreads = level_statistics(values, level, lo[k], lo[k] + g * width, g)
        channels.append(replace(channel, centres=centres, spreads=spreads,
                                correlation=residual_correlation(values, level, centres)))
    return Model(pca.mean, pca.basis, sample.min(axis=axes), sample.max(axis=axes),
                 tuple(channels),
                 {"max_offset": max_offset, "threshold": threshold, "levels": levels})


def fit_labels(labels: np.ndarray, classes: int, *, seed: int | np.random.Generator = 0,
               max_offset: int = MAX_OFFSET, threshold: float = THRESHOLD,
               max_cliques: int = MAX_CLIQUES, selection_size: int = SELECTION_SIZE,
               progress: Callable[[float, str], object] | None = None) -> Model:
    """The clique model of a label map (int (H, W), labels 0..classes-1): the label texture."""
    rng, report = budget.start(seed, progress)
    levels = label_levels(classes)
    channel = fit_channel(levels[labels], levels, 0.0, classes - 1.0, rng, max_offset,
                          threshold, max_cliques, selection_size, SELECTION_SWEEPS,
                          categorical=True, progress=report)
    one = np.ones(1, np.float32)
    return Model(np.zeros(1, np.float32), np.eye(1, dtype=np.float32), 0 * one,
                 one * (classes - 1), (channel,), {"labels": classes})



def synthesize_channel(channel: ChannelModel, shape, rng: np.random.Generator,
                       sweeps: int = SWEEPS, progress: Progress | None = None,
                       start: np.ndarray | None = None) -> np.ndarray:
    """Marks (H, W) synthesized on a torus from one channel's model, starting from noise drawn
    from its singleton histogram, or from the marks ``start`` (H, W) when given: a coarser
    synthesis, which is refined by steps of one level and draws from the singleton target,
    each clipped to the range of the pixel's 8 neighbours (``Relaxation``'s ``bounded``).
    Unbounded, a proposal puts a level far from a settled neighbourhood's into it, and at zero
    temperature such a pixel stays wherever it lowers E: an isolated extreme pixel (21 per
    mil of the pixels of a 1024^2 synthesis of the setts photo were 3 levels or more from all
    8 neighbours after the refining sweeps, none in their start)."""
    progress = progress or Progress()
    p = np.asarray(channel.singleton, np.float64)
    given = start
    if start is None:
        start = rng.choice(channel.levels, size=shape, p=p / p.sum())
    relax = Relaxation(start, channel.levels, p, channel.terms(),
                       step=0 if channel.categorical else STEP if given is None else 1,
                       tick=lambda: progress(0.0, "counting the clique histograms"),
                       bounded=given is not None)
    relax.run(sweeps, rng, progress)
    return relax.image


def relax(model: Model, width: int, height: int, rng: np.random.Generator,
          report: Progress, sweeps: int = SWEEPS, start: np.ndarray | None = None
          ) -> np.ndarray:
    """A periodic (height, width, C) float32 image from ``model`` alone, by stochastic
    relaxation of each channel (:func:`synthesize_channel`); arguments as checked by
    :meth:`Model.synthesize`, the public entry.

    A label-map model gives int32 (height, width) labels instead. ``start``: an image
    (height, width, C) to relax from instead of noise (a coarser synthesis, upsampled).
    """
    out = []
    pca = ColorPCA(np.asarray(model.mean, np.float32), np.asarray(model.basis, np.float32))
    initial = None if start is None else pca.forward(np.asarray(start, np.float32))
    # a channel's share of the progress by its types (synthesis_cost) and levels: in equal
    # shares a component of 8 levels and 17 types had taken 60x the time of one of 2 and 1
    ends = np.cumsum([0.0] + [len(channel.levels) * (2.0 + len(channel.offsets))
                              for channel in model.channels])
    ends /= ends[-1]
    for k, channel in enumerate(model.channels):
        report(ends[k], "preparing the start" if initial is not None else "drawing the start")
        marks = None
        if initial is not None:
            g = len(channel.levels)
            marks = channel.levels[quantize(initial[:, :, k], channel.lo, channel.hi, g)]
        marks = synthesize_channel(channel, (height, width), rng, sweeps,
                                   report.span(ends[k], ends[k + 1]), marks)
        out.append(channel.decode(marks, rng))
    if model.channels[0].categorical:
        return out[0]
    image = pca.inverse(np.stack(out, axis=2))
    return np.clip(image, model.low, model.high).astype(np.float32)


#: Clique types a natural texture's selection typically ends with (the cost model's).
TYPICAL_TYPES = 20
#: Reference seconds of a type's selection sweep over a pixel of the torus, and of a synthesis
#: sweep over an output pixel per type (:func:`cost`). SWEEP_COST 3.8e-8 -> 5.1e-8 (issue 45:
#: the synthesis read 1.10-1.23x its model from 32^2-256^2 exemplars to 512^2-1024^2 and
#: 1.5-1.85x from the setts to 1024^2-2048^2, whose larger levels leave the caches).
SELECTION_COST, SWEEP_COST = 2.3e-6, 5.1e-8
#: The selection's weight in the progress' shares, against its term of the cost: the fit took
#: 0.19-0.33 of a run where the cost puts 0.41 (CPU time, 128 -> 256 crops of five photos,
#: grey and colour; the selection ends early in the weak components: 1-11 types, not 20);
#: 0.7 puts it at 0.31 (at 0.5, 0.26: the grey brick's fit then read 1.8x at 10 %). The
#: prediction keeps the whole term (fitted on whole runs).
SELECTION_WEIGHT = 0.7


def sampled_pixels(shape, max_offset: int) -> int:
    """Pixels of the sample an exemplar of ``shape`` is analysed on (``cliques.strips``)."""
    h, w = shape[:2]
    m = reach(max_offset, shape)
    count = -(-ANCHORS // w)
    return h * w if h * w <= ANCHORS or count >= h - m else count * (m + 1) * w


def fit_share(shape, width, height, params) -> float:
    """The fit's share of the progress of a fit and synthesis (:func:`cost`'s terms), with
    the selection at ``SELECTION_WEIGHT`` of its term."""
    synthesis = synthesis_cost(shape[2], min(params["max_cliques"], TYPICAL_TYPES), width,
                               height, params["sweeps"])
    whole = cost(shape, width, height, params)
    fit = whole - synthesis - (1.0 - SELECTION_WEIGHT) * selection_cost(shape, params)
    return fit / (fit + synthesis)


def selection_cost(shape, params) -> float:
    """Seconds of the selection (:func:`cost`): a round of sweeps over the selection torus per
    selected type and colour component."""
    h, w, c = shape
    torus = min(h, SELECTION_SIZE) * min(w, SELECTION_SIZE)
    return SELECTION_COST * c * min(params["max_cliques"], TYPICAL_TYPES) * SELECTION_SWEEPS \
        * torus


def cost(shape, width, height, params):
    """Exemplar statistics: the clique histograms of every candidate type on at most
    ``ANCHORS`` heads and the colour work on the sampled strips; selection: a round of sweeps
    over the selection torus per selected type and colour component; synthesis: ``sweeps``
    over the output with every selected type from both ends. Selection stops at the
    threshold, after about ``TYPICAL_TYPES`` types on natural textures (measured:
    ``max_cliques`` 20 and 40 take about the same time). The statistics' coefficients refitted
    on the setts' 256^2 and 1024^2 crops and its 12 MP photo, two and three levels each (the
    anchors' 1.5e-7 -> 1.6e-6 since the levels' means, spreads and correlations are read from
    the exemplar: the 1024 crop's fit read 6.2 reference seconds against 0.98 told)."""
    h, w, c = shape
    t = min(params["max_cliques"], TYPICAL_TYPES)
    statistics = c * (1.6e-6 * min(h * w, ANCHORS)
                      + 1.1e-7 * sampled_pixels(shape, params["max_offset"]))
    return 0.05 + statistics + selection_cost(shape, params) + synthesis_cost(c, t, width, height,
                                                                          params["sweeps"])


def synthesis_cost(channels, types, width, height, sweeps):
    """Synthesis from a fitted clique model: ``sweeps`` over the output per channel, every
    selected type looked at from both ends."""
    return SWEEP_COST * channels * sweeps * width * height * (2 + types)
