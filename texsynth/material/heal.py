"""Heal a masked region of a photo from the rest of it, as Resynthesizer's Heal Selection.

The region is filled from the outside in by copied photo patches, then its level is corrected
in the gradient domain, as ``texsynth.tileable`` fills its band:

- fill order (Criminisi, Pérez & Toyama 2004, 3, the confidence term): the next patch is
  centred on the pixel of the fill front whose ``P`` x ``P`` window holds the most pixels
  already known (photo or filled), so the fill proceeds as an onion peel and every patch is
  matched on at least half a window;
- patch choice (Efros & Freeman 2001, 2.1): the SSD of every photo window wholly outside the
  mask with what is known of the window to fill (``texsynth.blocks.quilting.Search``, the
  squares expanded as FFT correlations), at random among the ``CANDIDATES`` best within
  ``TOLERANCE`` of the best; the window's unknown pixels are copied whole (never averaged:
  the region is as sharp as the photo);
- guided interpolation (Pérez, Gangnet & Blake 2003, 3): inside the region the result is the
  function whose gradient is the copied pieces' own (across a cut, the nearer of the two
  pieces' gradients: ``texsynth.blocks.poisson.guidance``) and which equals the photo at the
  region's boundary: the level difference between the pieces and their surroundings is spread
  over the region and the boundary shows no step. Screened (Bhat, Curless, Cohen & Seitz 2008,
  2): the least squares also holds the result to the pieces, so each step is taken out within
  about ``SCREEN`` patch of it. Solved exactly (sparse LU).

Deviations, one line each:
- the patch side ``P`` is the photo's texel size (``texsynth.blocks.period``) clipped to
  [``MIN_PATCH``, ``MAX_PATCH``] and to a third of the region's surroundings;
- the patches come from a window around the mask (``CONTEXT`` times the mask's extent beyond
  it, at least ``MIN_CONTEXT`` pixels): a blemish on a 12 MP photo searches a neighbourhood,
  not the whole photo (Resynthesizer's "context sampling" default is similar);
- Criminisi et al.'s data term (isophotes into the front) is left out: the patches are matched
  on half their window or more, which continues edges through the SSD;
- no minimum error boundary cut (Efros & Freeman 2.1): a patch fills only the pixels still
  unknown, its edge with the earlier ones and the photo where the SSD placed it; the guided
  interpolation then takes out the step of level there (the pieces' gradients, not their
  difference, guide it). A graph cut (Kwatra et al. 2003, 3.1) letting each patch take over
  earlier ones where they agree was tried and measured worse (the section's 12 cases at seeds
  0 and 1: 7 and 6 within both goals against 8 and 9 without: more, shorter cuts in a small
  region left its gradient ratio at 0.81-0.85 on the thin blemishes);
- the guidance never reads the photo under the mask (the blemish): a piece's gradient that
  would (the photo's own pixel next to the boundary, a patch taken beside the mask) is not
  offered (``guidance``'s ``readable``);
- the correction is clipped to the photo's range in each channel;
- the pairs across the region's boundary weigh ``BOUNDARY_WEIGHT`` (1.5) in the least squares:
  at 1 the misfit the cuts' steps leave lands on the boundary as much as inside, its jump above
  the guidance there (the gravel sign: 0.144 against the pieces' 0.10-0.12), a seam (the
  section's gravel butt 1.22 -> 1.16, gravel sign 1.20 -> 1.13; within both goals at seeds 0-3
  11, 10, 11, 12 -> 12, 11, 12, 12 of 12). The pieces' gradient there is the SSD's, smoother than
  the photo's on the grass: at 2 its sign's seam read 0.80 at seed 2 (out; 12, 11, 11, 12), at 4
  the grass and gravelly dirt signs' 0.82 and 0.80 at seed 0;
- screened (lambda = 1 / (``SCREEN`` p)^2, Bhat et al.'s data term on the pieces): taken out all
  the way, the cuts' steps, one-signed where the pebbles' shading is one-sided, summed over the
  onion peel's layers to a drift of the region's level (the gravel sign 0.047 darker than the
  pieces copied; at seeds 0-4 -0.047 to +0.034; screened -0.008 to +0.006; its region 0.053 ->
  0.014 darker than the truth, the correction's deviation 0.074 -> 0.061). The pieces' level is
  the SSD's: on the asphalt, where the draw's windows of more gradient are brighter, the region
  now reads that (sign +0.016, butt +0.026 over the truth, from -0.002, +0.004);
- across a cut the guidance takes one piece's gradient for every channel (``guidance``'s
  ``joint``): chosen per channel, a pixel's colour mixed two pieces' and the correction showed
  green and violet specks, a tinted haze in the cigarette butts (the section's high-frequency
  chroma over the truth's: gravel butt 1.11 -> 1.03, brick butt 1.34 -> 1.19; both goals the same;
  a trade: the asphalt butt's mean chroma 0.90 -> 0.85, the gravelly dirt butt's high-frequency
  chroma 0.72 -> 0.65);
- the draw among the candidates is only among those whose window holds at least their mean
  gradient (sum of |forward differences|): the SSD favours smooth windows, and the onion peel
  compounds it (the section's gravelly dirt butt gradient 0.85 -> 0.91, asphalt sign 0.89 ->
  1.07; the gravel sign's seam 1.07 -> 1.20). Taking the most textured candidate outright read
  the same gradients, the gravel sign's seam 1.22, and left the seed no part.

- a region wider than a patch is first tried as one copy (Harrison 2005 grows it from one
  neighbourhood match; here the offset whose ``RING`` px ring of known pixels around the mask
  matches best, on the same FFT SSD): taken when its SSD per pixel is below ``WHOLE`` of two
  unrelated pixels' (twice the variance), which only a regular texture reaches, its lattice
  shift (the section's brick sign 0.47; the stochastic photos 0.58-0.88): the bricks stay whole
  and in phase, where the onion peel broke courses (seam 0.66 -> 1.07, gradient 0.93 -> 1.03).
  The ring of 8 px placed it 1-2 px off the mortar (seam 0.77); at 0.6 the concrete pavers'
  sign (0.58) was copied from a smoother stretch (gradient 0.95 -> 0.78); thin regions (the
  cigarette butts) copied whole read gradient 0.79 on the brick.

- a region of at most ``DRAW_PIXELS`` pixels (the cigarette butts: 1900) is filled
  ``DRAWS`` times and the draw kept whose boundary jump is nearest the photo's own one pixel
  further out (``_boundary_misfit``: the photo around, never the truth): the gravel's butt
  seam 1.46 -> 1.22 (its 12 draws read 1.20-1.49, the misfit ranking them as the seam does),
  the other butts 0.96-1.03; the butts take about 4 times as long (gravel: 1.7 -> 6.2 s).

All 12 of the material section's cases are within the goals (gradient ratio 0.9-1.1, boundary
seam ratio 0.8-1.2) at seed 0 (``python -m benchmarks.heal_cases``), and at seeds 2 and 3; at
seed 1 the gravel's cigarette butt reads seam 1.24. The photo under that butt is smoother along
its outline than anywhere: its luminance jump across the mask's boundary (0.085) is below the
same outline's at each of 300 other places in the photo (median 0.127). Tried before the
boundary's weight: the boundary's guidance scaled down to the photo's jump beside it (a no-op
there; the brick sign 1.07 -> 0.90); the draws among all candidates (1.34, the gravelly dirt
butt's gradient 0.83); the boundary's guidance halved or zeroed (the other butts 0.80-0.93,
0.71-0.85: a trade); patches of 10 / 24 px; drawn among 1 or 8 within 25%; the SSD weighting
the front 4 times: the same or worse.
The draw's energy over the windows' level (a contrast, not a gradient: no preference for bright
windows) read the asphalt 0.005 and 0.002 over the truth, but within both goals 12, 11, 11, 11
of 12 at seeds 0-3 (the boundary's weight 2): left out.

The haze left (issue 43): the correction's deviation (0.03-0.06) is the cuts' steps taken out
within half a patch of each, a grey smudge there on the gravel. Tried: the steps between two
pieces kept (only the boundary corrected): the pieces' seams show (the brick butt's high-frequency
chroma 1.81; gravel sign seam 1.21, gravel butt gradient 1.13); kept only where no larger than the
pieces' own gradients there: the same; each step replaced by its mean over the cut between the
same two pieces (only their level taken out): the drift the same (0.047), the gradients up (the
gravel butt 1.10), the boundary's seam 1.62 when it too; the clip to the range of all channels:
no pixel changes.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sparse
import scipy.sparse.linalg as sparse_linalg
from scipy.ndimage import binary_dilation, distance_transform_edt, uniform_filter

from .. import budget, validation
from ..blocks.parallel import serial_blas
from ..blocks.period import texel_size
from ..blocks.poisson import guidance
from ..blocks.quilting import Search

__all__ = ["heal", "check_mask"]

#: Patch side bounds (pixels).
MIN_PATCH, MAX_PATCH = 16, 48
#: The search window around the mask: this many times its extent beyond it, at least
#: ``MIN_CONTEXT`` pixels.
CONTEXT, MIN_CONTEXT = 1.0, 96
#: Candidates drawn among, and their SSD's tolerance over the best (Efros & Freeman 2.1).
CANDIDATES, TOLERANCE = 4, 0.1
#: The whole-region copy: the ring of known pixels it is matched on (pixels), and the largest
#: ring SSD per pixel, over that of two unrelated pixels (twice the variance), it is taken at.
RING, WHOLE = 4, 0.5
#: Regions of at most ``DRAW_PIXELS`` pixels are filled ``DRAWS`` times, the draw kept whose
#: boundary jump is nearest the photo's own jumps beside it.
DRAWS, DRAW_PIXELS = 4, 4096
#: The guided interpolation's screening length, in patches: the pieces' own level holds beyond
#: it (lambda = 1 / (SCREEN p)^2).
SCREEN = 0.5
#: The weight of the pairs across the region's boundary in the guided interpolation.
BOUNDARY_WEIGHT = 1.5


def check_mask(mask, shape) -> np.ndarray:
    """``mask`` as a bool (H, W) array for a photo of ``shape``, or ``ValueError`` saying what is
    wrong: not (H, W), not finite, marking nothing, or marking every pixel.

    Examples
    --------
    >>> int(check_mask(np.eye(4) > 0, (4, 4, 3)).sum())
    4
    >>> check_mask(np.zeros((4, 4)), (4, 4, 3))
    Traceback (most recent call last):
    ...
    ValueError: mask marks no pixel to heal; paint the region to re-synthesize (True or 1)
    """
    m = np.asarray(mask)
    if m.ndim == 3 and m.shape[2] == 1:
        m = m[:, :, 0]
    if m.shape != tuple(shape[:2]):
        raise ValueError(f"mask must be (H, W) = {tuple(shape[:2])}, the photo's size, got "
                         f"shape {m.shape}")
    if m.dtype != bool:
        if m.dtype.kind not in "fiu":
            raise ValueError(f"mask must be bool or numeric, got dtype {m.dtype}")
        if not np.isfinite(m).all():
            raise ValueError("mask contains NaN or infinite values")
        m = m > (0.5 if m.dtype.kind == "f" else np.iinfo(m.dtype).max // 2 if m.dtype.kind
                 == "u" and m.max() > 1 else 0)
    if not m.any():
        raise ValueError("mask marks no pixel to heal; paint the region to re-synthesize "
                         "(True or 1)")
    if m.all():
        raise ValueError("mask covers the whole photo: nothing is left to heal it from; "
                         "mark only the blemish")
    return m


def _window(m: np.ndarray) -> tuple[slice, slice]:
    """The search window around the mask's bounding box."""
    rows, cols = np.nonzero(m.any(axis=1))[0], np.nonzero(m.any(axis=0))[0]
    extent = max(rows[-1] - rows[0] + 1, cols[-1] - cols[0] + 1)
    reach = int(max(MIN_CONTEXT, CONTEXT * extent))
    h, w = m.shape
    return (slice(max(0, rows[0] - reach), min(h, rows[-1] + 1 + reach)),
            slice(max(0, cols[0] - reach), min(w, cols[-1] + 1 + reach)))


@serial_blas()
def heal(photo, mask, *, seed: int = 0, patch: int | None = None,
         progress: Callable[[float, str], object] | None = None) -> np.ndarray:
    """``photo`` (H, W) or (H, W, C) with the region ``mask`` (H, W) marks (True / 1)
    re-synthesized from the rest of it; every unmasked pixel unchanged. float32.

    Parameters
    ----------
    photo : array (H, W) or (H, W, C).
    mask : array (H, W), bool or numbers (above one half: heal).
    seed : the patch choices' seed; same inputs and seed, identical output.
    patch : patch side in pixels (default: the texel size, within [16, 48]).
    progress : ``progress(fraction, message)``; returning False cancels (``Cancelled``).

    References
    ----------
    Criminisi, Pérez & Toyama 2004, "Region filling and object removal by exemplar-based image
    inpainting", 3 (fill order); Efros & Freeman 2001, "Image quilting for texture synthesis
    and transfer", 2.1 (patch choice); Pérez, Gangnet & Blake
    2003, "Poisson image editing", 3 (guided interpolation); Bhat, Curless, Cohen & Seitz 2008,
    "Fourier analysis of the 2D screened Poisson equation for gradient domain problems", 2 (the
    screening); Harrison 2005, "Image texture tools" (Resynthesizer's Heal Selection, the task).

    Examples
    --------
    >>> y, x = np.mgrid[:64, :64]
    >>> photo = (0.5 + 0.3 * np.sin(x / 2.0) * np.cos(y / 3.0))[:, :, None].repeat(3, 2)
    >>> mask = np.zeros((64, 64), bool); mask[24:36, 20:40] = True
    >>> blemished = np.where(mask[:, :, None], 1.0, photo).astype(np.float32)
    >>> healed = heal(blemished, mask)
    >>> bool((healed[~mask] == blemished[~mask]).all()), bool(healed[mask].max() < 0.9)
    (True, True)
    """
    given = np.asarray(photo)
    a = validation.image(given, what="photo", channels=None)
    m = check_mask(mask, a.shape)
    rng, report = budget.start(seed, progress)
    rows, cols = _window(m)
    region, hole = a[rows, cols], m[rows, cols]
    h, w = hole.shape
    if patch is None:  # the texel size of the photo around, the blemish made its mean
        rgb = region[:, :, :3]
        plain = np.where(hole[:, :, None], rgb[~hole].mean(axis=0), rgb)
        patch = int(np.clip(round(texel_size(plain)), MIN_PATCH,
                            max(MIN_PATCH, min(MAX_PATCH, min(h, w) // 3))))
    p = validation.whole(patch, "patch", 2, max(2, min(h, w) // 3))
    # Source windows: every p x p window with no masked pixel (top-left corners).
    counts = uniform_filter(hole.astype(np.float64), p, mode="constant",
                            origin=(-(p // 2), -(p // 2)))[:h - p + 1, :w - p + 1]
    valid = counts < 0.5 / (p * p)
    if not valid.any():
        raise ValueError(f"mask leaves no {p} x {p} window of the photo to heal from; "
                         "mark a smaller region or pass a smaller patch")
    report(0.0, "Heal: filling")
    # A region wider than a patch is tried whole first (the onion peel would meet itself).
    whole = _whole(region, hole) if 2 * distance_transform_edt(hole).max() > p else None
    draws = 1 if whole or hole.sum() > DRAW_PIXELS else DRAWS
    best = (np.inf, None)
    for k in range(draws):  # the first draw is the one a single draw gives
        out, positions = whole or _fill(region, hole, valid, p, rng,
                                        report.span(0.8 * k / draws, 0.8 * (k + 1) / draws))
        healed = _blend(region, out, positions, hole, p)
        best = min(best, (_boundary_misfit(healed, hole), k, healed), key=lambda t: t[:2])
    report(0.8, "Heal: blending the boundary")
    healed = best[2]
    result = a.copy()
    result[rows, cols] = np.where(hole[:, :, None], healed, region)
    report(1.0, "Heal: done")
    return result.reshape(given.shape) if given.ndim == 2 else result


def _boundary_misfit(image, hole) -> float:
    """|log| of the mean jump (sum of |channel differences|) across the hole's boundary over the
    mean jump one pixel further out, between known pixels in the same direction: 0 when the
    boundary shows as the photo around it does, above a seam, below a soft edge."""
    jumps = []
    for axis in (0, 1):
        for step in (1, -1):
            a, b, c = hole, np.roll(hole, -step, axis), np.roll(hole, -2 * step, axis)
            f1, f2 = np.roll(image, -step, axis), np.roll(image, -2 * step, axis)
            edge = np.ones_like(hole)  # pairs that np.roll wrapped left out
            index = np.arange(hole.shape[axis])
            inside = (index + 2 * step >= 0) & (index + 2 * step < hole.shape[axis])
            edge &= inside[:, None] if axis == 0 else inside[None, :]
            across = edge & a & ~b
            beyond = across & ~c
            jumps.append((np.abs(f1 - image).sum(2)[across], np.abs(f2 - f1).sum(2)[beyond]))
    shown = np.concatenate([j[0] for j in jumps]).mean()
    around = np.concatenate([j[1] for j in jumps])
    return float(abs(np.log(max(shown, 1e-12) / max(around.mean() if around.size else 0,
                                                     1e-12))))


def _whole(source, hole):
    """The region copied whole from the offset whose ``RING`` px ring of known pixels matches
    the mask's best (a regular texture's lattice shift: bricks stay whole), as (the filled
    image, its position map), or None when the best match is no better than ``WHOLE``."""
    h, w = hole.shape
    big = binary_dilation(hole, iterations=RING)
    ys, xs = np.nonzero(big)
    top, left = ys.min(), xs.min()
    bh, bw = ys.max() - top + 1, xs.max() - left + 1
    box = (slice(top, top + bh), slice(left, left + bw))
    ring = (big & ~hole)[box]
    ssd = Search(source).ssd(source[box], ring.astype(np.float64))
    covered = uniform_filter(hole.astype(np.float64), (bh, bw), mode="constant",
                             origin=(-(bh // 2), -(bw // 2)))[:ssd.shape[0], :ssd.shape[1]]
    ssd = np.where(covered < 0.5 / (bh * bw), ssd, np.inf)
    variance = source[~hole].var(axis=0).sum()
    if not np.isfinite(ssd.min()) or ssd.min() > WHOLE * 2 * variance * ring.sum():
        return None
    si, sj = np.unravel_index(int(ssd.argmin()), ssd.shape)
    di, dj = si - top, sj - left
    positions = np.moveaxis(np.indices((h, w), np.int32), 0, 2).copy()
    positions[hole] += np.int32([di, dj])
    out = source.copy()
    out[hole] = source[positions[hole][:, 0], positions[hole][:, 1]]
    return out, positions


def _fill(source, hole, valid, p, rng, report):
    """The onion-peel patch fill: (the filled image, its position map (h, w, 2))."""
    h, w = hole.shape
    search = Search(source)
    g = np.abs(np.diff(source, axis=0, append=source[-1:])).sum(2) + np.abs(
        np.diff(source, axis=1, append=source[:, -1:])).sum(2)
    energy = uniform_filter(g, p, mode="constant", origin=(-(p // 2), -(p // 2)))[
        :h - p + 1, :w - p + 1]
    out = source.copy()
    positions = np.moveaxis(np.indices((h, w), np.int32), 0, 2).copy()
    filled = ~hole
    total = int(hole.sum())
    while not filled.all():
        front = ~filled & binary_dilation(filled)
        confidence = uniform_filter(filled.astype(np.float64), p, mode="constant")
        i, j = np.unravel_index(np.where(front, confidence, -1.0).argmax(), (h, w))
        top = int(np.clip(i - p // 2, 0, h - p))
        left = int(np.clip(j - p // 2, 0, w - p))
        window = (slice(top, top + p), slice(left, left + p))
        known = filled[window]
        ssd = search.ssd(out[window], known.astype(np.float64))
        ssd = np.where(valid, ssd, np.inf)
        flat = ssd.ravel()
        best = np.argpartition(flat, CANDIDATES)[:CANDIDATES]
        best = best[flat[best] <= flat[best].min() * (1 + TOLERANCE) + 1e-12]
        e = energy.ravel()[best]
        si, sj = np.unravel_index(int(rng.choice(np.sort(best[e >= e.mean()]))), ssd.shape)
        patch = source[si:si + p, sj:sj + p]
        o, pos = out[window], positions[window]
        new = ~known
        o[new] = patch[new]
        pos[new] = (np.moveaxis(np.indices((p, p), np.int32), 0, 2) + [si, sj])[new]
        filled[window] = True
        report(1.0 - float((~filled).sum()) / total, "Heal: filling")
    return out, positions


def _blend(source, out, positions, hole, p):
    """Pérez et al. 2003, 3, on the hole, screened (Bhat et al. 2008, 2) and with the boundary's
    pairs weighted: the least squares sum_pq w_pq (f_p - f_q - v_pq)^2 + lambda sum_p (f_p - o_p)^2
    over the pairs with a pixel p in the hole, f_q = f*_q outside, v_pq = f_p - f_q of the pieces
    (``guidance``), o the pieces, lambda = 1 / (``SCREEN`` p)^2, w_pq = ``BOUNDARY_WEIGHT`` across
    the boundary and 1 inside; its normal equations
    (sum_q w_pq + lambda) f_p - sum_{q in the hole} w_pq f_q
    = sum_{q outside} w_pq f*_q + sum_q w_pq v_pq + lambda o_p, exactly, every channel at once."""
    h, w = hole.shape
    index = -np.ones((h, w), np.int64)
    n = int(hole.sum())
    index[hole] = np.arange(n)
    screen = 1.0 / (SCREEN * p) ** 2
    rhs = screen * out[hole].astype(np.float64)
    diagonal = np.full(n, screen)
    rows, cols, weights = [np.arange(n)], [np.arange(n)], [diagonal]
    for di, dj in ((1, 0), (0, 1)):
        # Every pair (a, b = a + step) with a pixel in the hole; g = f_b - f_a of the pieces.
        ai, aj = np.nonzero(hole[:h - di, :w - dj] | hole[di:, dj:])
        bi, bj = ai + di, aj + dj
        g = guidance(source, positions[ai, aj], positions[bi, bj], (di, dj), ~hole,
                     joint=True)
        ka, kb = index[ai, aj], index[bi, bj]
        w_ab = np.where((ka >= 0) & (kb >= 0), 1.0, BOUNDARY_WEIGHT)
        for k, other, sign, oi, oj in ((ka, kb, -1.0, bi, bj), (kb, ka, 1.0, ai, aj)):
            here = k >= 0
            np.add.at(diagonal, k[here], w_ab[here])
            np.add.at(rhs, k[here], (sign * w_ab[:, None] * g)[here])
            free = here & (other >= 0)
            rows.append(k[free])
            cols.append(other[free])
            weights.append(-w_ab[free])
            fixed = here & (other < 0)
            np.add.at(rhs, k[fixed], w_ab[fixed, None] * out[oi[fixed], oj[fixed]])
    a = sparse.csc_matrix((np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n, n))
    f = sparse_linalg.splu(a).solve(rhs)
    lo, hi = source.min(axis=(0, 1)), source.max(axis=(0, 1))
    healed = out.copy()
    healed[hole] = np.clip(f, lo, hi).astype(np.float32)
    return healed
