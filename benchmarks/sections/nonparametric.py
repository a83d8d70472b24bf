"""Efros-Leung and the multiscale MRF (issue 5; Forsyth & Ponce sec. 11.3.4, Torralba, Isola &
Freeman sec. 28.4, Neubeck et al. 2004 sec. 3.1), beside the Resynthesizer engine in the same run.

Evidence: multiscale_mrf 256 -> 512 against Resynthesizer on every texture (time, patch distance,
copy share, seam ratio; contact sheets); efros_leung 128 -> 256 with window 11 and the
brute-force cost of the same run extrapolated from timed pixels; the window-size effect of
Torralba, Isola & Freeman fig. 28.11; a position map pictured and re-applied to another map; 2048^2
time and peak memory.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

import texsynth
from benchmarks import peers
from benchmarks.context import fmt, timed
from texsynth import metrics
from texsynth.blocks.search import gaussian_weights, square_offsets

ORDER = 50
TITLE = "Non-parametric: Efros-Leung and the multiscale MRF (issue 5)"

SEED = 0
SHEET_ROWS = 6


def _crop(image, side):
    return np.ascontiguousarray(image[:side, :side, :3])


def _resynthesizer():
    peer = next(p for p in peers.peers() if p.name == "resynthesizer")
    return peer if peer.missing is None else None


def _fill_patch(exemplar, output) -> float:
    """Median patch distance of the output rows below the exemplar's height: all of it synthesized
    on Resynthesizer's canvas, whose top-left corner is the exemplar itself."""
    return metrics.patch_distance(exemplar, output[exemplar.shape[0]:])["median"]


def _mrf_vs_resynthesizer(ctx, side, out_side):
    """multiscale_mrf and Resynthesizer on every texture: table rows, sheets, ratios."""
    rs = _resynthesizer()
    lines = ["| texture | MRF s | Resynth. s | MRF patch d. | Resynth. patch d. | MRF copy | "
             "Resynth. copy | MRF seam | Resynth. seam | MRF / Resynth. patch d., fill only |",
             "|---" * 10 + "|"]
    rows, sheets, ratio, stats = [], [], [], {"mrf": [], "rs": []}
    for tex in ctx.textures:
        ex = _crop(tex.image, side)
        m_time, (out, positions) = timed(lambda ex=ex: texsynth.synthesize_positions(
            ex, out_side, out_side, method="multiscale_mrf", seed=SEED))
        q = ctx.quality(ex, out)
        q["fill_patch"] = _fill_patch(ex, out)
        stats["mrf"].append(q)
        cells = [ex, out, texsynth.positions_image(positions, ex.shape)]
        r_time, rq = None, {}
        if rs is not None:
            r_time, r_out = timed(lambda ex=ex: rs.run(ex, out_side, out_side, SEED))
            rq = ctx.quality(ex, r_out)
            rq["fill_patch"] = _fill_patch(ex, r_out)
            stats["rs"].append(rq)
            ratio.append(m_time / r_time)
            cells.insert(2, r_out)
        rows.append(cells)
        lines.append(f"| {tex.short} | {m_time:.2f} | {fmt(r_time, 2)} | "
                     f"{fmt(q['patch_distance'])} | {fmt(rq.get('patch_distance'))} | "
                     f"{q['copy_share']:.2f} | {fmt(rq.get('copy_share'), 2)} | "
                     f"{q['seam_ratio']:.2f} | {fmt(rq.get('seam_ratio'), 2)} | "
                     f"{q['fill_patch']:.3f} / {fmt(rq.get('fill_patch'))} |")
    columns = ["exemplar", "multiscale_mrf"] + (["Resynthesizer"] if rs else []) + ["positions"]
    for i in range(0, len(rows), SHEET_ROWS):
        sheets.append(ctx.contact_sheet(f"nonparametric_mrf_{i // SHEET_ROWS}.png", columns,
                                        rows[i:i + SHEET_ROWS]))
    return lines, sheets, ratio, stats, rs


def _median(stats, key):
    values = [q[key] for q in stats]
    return statistics.median(values) if values else float("nan")


def _brute_force_seconds(exemplar, window, pixels, samples=24, seed=0):
    """Seconds for Efros-Leung's search done pixel by pixel (every exemplar window compared
    directly, no matrix product, no bound), extrapolated from ``samples`` timed pixels."""
    rng = np.random.default_rng(seed)
    offsets = square_offsets(window)
    r = window // 2
    h, w, c = exemplar.shape
    pr, pc = np.meshgrid(np.arange(r, h - r), np.arange(r, w - r), indexing="ij")
    windows = exemplar[pr.ravel()[:, None] + offsets[:, 0], pc.ravel()[:, None] + offsets[:, 1]]
    gauss = gaussian_weights(offsets, window / 6.4)
    start = time.perf_counter()
    for _ in range(samples):
        known = (rng.random(len(offsets)) < 0.5).astype(np.float32)
        g = gauss * known / (gauss * known).sum()
        n = rng.random((len(offsets), c), dtype=np.float32)
        d = (g[None, :, None] * (windows - n) ** 2).sum(axis=(1, 2))
        best = d.min()
        rng.choice(np.flatnonzero(d <= 1.1 * best))
    return (time.perf_counter() - start) / samples * pixels


def _efros_leung(ctx, names, side, out_side):
    lines = ["| texture | time s | brute force s (extrapolated) | speed-up | patch d. | "
             "copy | seam |", "|---" * 7 + "|"]
    rows = []
    for tex in [t for t in ctx.textures if t.short in names] or ctx.textures[:1]:
        ex = _crop(tex.image, side)
        m = ctx.measure(lambda ex=ex: texsynth.synthesize_positions(
            ex, out_side, out_side, method="efros_leung", seed=SEED, window=11), repeats=1)
        out, positions = m.result
        brute = _brute_force_seconds(ex, 11, out_side * out_side)
        q = ctx.quality(ex, out)
        rows.append([ex, out, texsynth.positions_image(positions, ex.shape)])
        lines.append(f"| {tex.short} | {m.median_s:.2f} | {brute:.0f} | {brute / m.median_s:.0f}x"
                     f" | {fmt(q['patch_distance'])} | {q['copy_share']:.2f} | "
                     f"{q['seam_ratio']:.2f} |")
    sheet = ctx.contact_sheet("nonparametric_el.png", ["exemplar", "efros_leung (11)",
                                                       "positions"], rows)
    return lines, sheet


def _window_sweep(ctx, name, side, out_side, windows):
    tex = next((t for t in ctx.textures if t.short == name), ctx.textures[0])
    ex = _crop(tex.image, side)
    outs, times = [ex], []
    for k in windows:
        start = time.perf_counter()
        outs.append(texsynth.synthesize(ex, out_side, out_side, method="efros_leung", seed=SEED,
                                        window=k))
        times.append(time.perf_counter() - start)
    sheet = ctx.contact_sheet("nonparametric_el_windows.png",
                              ["exemplar"] + [f"window {k}" for k in windows], [outs],
                              cell=out_side)
    return sheet, tex.short, times


def _follow_map(ctx, name, side, out_side):
    """A position map pictured, and re-applied to a second map of the same exemplar."""
    tex = next((t for t in ctx.textures if t.short == name), ctx.textures[0])
    ex = _crop(tex.image, side)
    out, positions = texsynth.synthesize_positions(ex, out_side, out_side,
                                                   method="multiscale_mrf", seed=SEED)
    # A stand-in for a second map of the material: the exemplar's gradient magnitude.
    y = ex.mean(axis=2)
    edges = np.hypot(*np.gradient(y))
    edges = np.repeat((edges / max(edges.max(), 1e-6))[:, :, None], 3, axis=2)
    moved = texsynth.apply_positions(positions, edges)
    exact = np.array_equal(texsynth.apply_positions(positions, ex), out)
    sheet = ctx.contact_sheet("nonparametric_positions.png",
                              ["exemplar", "output", "position map (x red, y green)",
                               "second map", "second map, same positions"],
                              [[ex, out, texsynth.positions_image(positions, ex.shape), edges,
                                moved]], cell=min(out_side, 256))
    return sheet, tex.short, exact


def _large(ctx, sizes):
    lines = ["| method | exemplar | output | time s | peak MiB (tracemalloc) | RSS growth MiB | "
             "estimate MiB |", "|---" * 7 + "|"]
    tex = next((t for t in ctx.textures if t.short == "pebbles01"), ctx.textures[0])
    for method, side, params in (("multiscale_mrf", 256, {}), ("efros_leung", 64, {})):
        ex = _crop(tex.image, side)
        for out_side in sizes[method]:
            m = ctx.measure(lambda ex=ex, s=out_side, mt=method, p=params: texsynth.synthesize(
                ex, s, s, method=mt, seed=SEED, **p), repeats=1)
            method_rec = texsynth.get_method(method)
            estimate = method_rec.memory(ex.shape, out_side, out_side,
                                         method_rec.resolve(params)) / 2**20
            lines.append(f"| {method} | {ex.shape[1]}^2 | {out_side}^2 | {m.median_s:.1f} | "
                         f"{m.peak_mib:.0f} | {m.rss_mib:.0f} | {estimate:.0f} |")
    return lines


def run(ctx) -> str:
    quick = ctx.quick
    side, out_side = (128, 256) if quick else (256, 512)
    lines, sheets, ratio, stats, rs = _mrf_vs_resynthesizer(ctx, side, out_side)
    el_lines, el_sheet = _efros_leung(ctx, ("pebbles01",) if quick else
                                      ("pebbles01", "pool_water", "brick", "lattice_floor"),
                                      128 if not quick else 64, 256 if not quick else 128)
    windows = (5, 11) if quick else (5, 11, 17)
    sweep_sheet, sweep_name, sweep_times = _window_sweep(ctx, "pebbles01", 64 if quick else 96,
                                                         128 if quick else 192, windows)
    follow_sheet, follow_name, exact = _follow_map(ctx, "pebbles01", side, out_side)
    large = _large(ctx, {"multiscale_mrf": (512,) if quick else (1024, 2048),
                         "efros_leung": (128,) if quick else (512, 2048)})

    md = [
        "Both methods copy whole exemplar pixels, so they return a position map (row, col into "
        "the exemplar) through `texsynth.synthesize_positions`; `texsynth.apply_positions` "
        "re-applies it to another map of the material (the Blender operator "
        "`texsynth.synthesize_material`, mode Column, does this for the selected Image Texture "
        "nodes). Output "
        "neighbourhoods wrap around the canvas, so every result tiles.",
        "",
        f"### multiscale_mrf {side} -> {out_side}, beside Resynthesizer",
        "",
    ]
    if rs is None:
        md.append("Resynthesizer was not importable: its columns are empty "
                  "(pip install -r benchmarks/requirements.txt).")
    else:
        md.append(
            f"Same exemplars (the top-left {side} x {side} crop), same output size, one run each "
            f"in this process, bare wall time (no tracemalloc). Median over textures: time "
            f"ratio MRF / Resynthesizer "
            f"**{statistics.median(ratio):.2f}** (range {min(ratio):.2f}-{max(ratio):.2f}); "
            f"patch distance MRF {_median(stats['mrf'], 'patch_distance'):.3f} vs "
            f"Resynthesizer {_median(stats['rs'], 'patch_distance'):.3f}; copy share "
            f"{_median(stats['mrf'], 'copy_share'):.2f} vs "
            f"{_median(stats['rs'], 'copy_share'):.2f}; seam ratio "
            f"{_median(stats['mrf'], 'seam_ratio'):.2f} vs "
            f"{_median(stats['rs'], 'seam_ratio'):.2f}. Resynthesizer's canvas holds the exemplar "
            "itself in its corner (how the engine is driven), a quarter of its output copied "
            "verbatim, which its patch distance and copy share include; on the rows below the "
            "exemplar, all synthesized, the median patch distance is MRF "
            f"{_median(stats['mrf'], 'fill_patch'):.3f} vs Resynthesizer "
            f"{_median(stats['rs'], 'fill_patch'):.3f}.")
    md += ["", *lines, ""]
    md += [f"![multiscale_mrf sheet {i}]({s})" for i, s in enumerate(sheets)]
    md += ["", "Columns: exemplar | multiscale_mrf | Resynthesizer | the MRF's position map.", ""]
    md += [
        f"### efros_leung {128 if not quick else 64} -> {256 if not quick else 128}, window 11",
        "",
        "Exact search: every exemplar window is scored for every pixel, through a matrix "
        "product over a lower bound (the inner 7 x 7 of the window) and exact re-ranking of the "
        "windows the bound cannot exclude. The brute-force column is the same search pixel by "
        "pixel (every window's weighted SSD computed directly), timed on 24 pixels and "
        "multiplied by the pixel count.",
        "", *el_lines, "", f"![efros_leung]({el_sheet})", "",
        "Window size (Torralba, Isola & Freeman fig. 28.11, Forsyth & Ponce fig. 11.22) on "
        f"{sweep_name}: "
        + ", ".join(f"window {k}: {t:.1f} s" for k, t in zip(windows, sweep_times, strict=True))
        + ".", "", f"![window sweep]({sweep_sheet})", "",
        "### Position maps", "",
        f"{follow_name}: the position map pictured (x -> red, y -> green) and applied to a second "
        f"map (here the exemplar's gradient magnitude, standing in for a normal or height map). "
        f"`apply_positions(positions, exemplar)` reproduces the output bit for bit: {exact}.",
        "", f"![position map]({follow_sheet})", "",
        "### Large outputs: time and peak memory (tracemalloc)", "", *large, "",
    ]
    return "\n".join(md)
