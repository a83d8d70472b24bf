"""Texture optimisation with PatchMatch and uniform patch usage, periodic.

Kwatra, Essa, Bobick & Kwatra 2005, "Texture optimization for example-based synthesis":
the output X minimises the texture energy E_t(x; {z_p}) = sum_p ||x_p - z_p||^r over output
neighbourhoods x_p on a grid of spacing w/4, each z_p its nearest exemplar neighbourhood.
Alternating:

    M-step: z_p = the exemplar patch nearest x_p (here PatchMatch, Barnes et al. 2009, on the
            torus: ``texsynth.blocks.patchmatch``);
    E-step: x = the weighted average of the overlapping z_p, weights w_p = ||x_p - z_p||^(r - 2),
            r = 0.8 (IRLS for the robust energy);

coarse to fine over resolution levels, and at each level over patch sizes from large to small
(the paper uses 32, 16, 8; here ``sizes`` of them ending at ``patch_size``), starting from
random exemplar patches. Kaspar, Neubert, Lischinski, Pauly & Kopf 2015, "Self tuning texture
optimization": a term that keeps the patch usage uniform, so the output does not repeat a few
favourite patches. Its form here (ours, after the paper's occurrence penalty): each exemplar
patch's distance gets ``lambda * median(d) * max(0, n(z) / n_bar - 1)``, n(z) the uses of the
exemplar patches within a grid step of z, n_bar the uniform usage (at least 1), median(d) the
median matching distance of the previous iteration.

Why the averaged result smudged (measured at 1024 -> 2048 on a brick wall, the output after
each level and patch size against that level's exemplar): the gradient ratio was 0.63 after the
coarsest level, 0.78, 0.81, 0.92, 0.95 and 0.98 after the next; the layout (rows) was set, and
already broken, at the coarsest of three levels, where a 16 px patch spans two brick rows; and
the former final step, each pixel the voted pixel nearest the weighted average, rebuilt the
average's blur out of exemplar pixels. Taking the mode instead in every E-step (each pixel from
its best patch) leaves the random start a fixed point (the output stayed its 16 px squares), so
the averaging stays for the iterations and only the last pass of each level and size is the
mode; and the levels reach the exemplar's texel, as Kaspar et al. 2015, 4 choose patch sizes.

Why rows still broke (1024 -> 2048 on the brick wall, and a 512 crop -> 512): the output is a
few large verbatim copies, placed at the coarsest levels where a brick row is under a pixel, so
neighbouring copies met half a row apart along straight cuts, and no later patch move shifts a
whole copy (fewer levels gave more and shorter breaks: 3 or 4 levels against the texel's 6).
So after each coarse level and patch size the copies slide into phase
(``texsynth.blocks.region_shift``: shift-map labels, graph-cut seam costs, whole regions moved).

Why copies met along long straight cuts through setts and bricks (the position maps of a 512
crop -> 1024 of the brick wall: 21 boundaries of 64 px or more along one row or column line,
the longest 226 px): the non-averaged pass gives each pixel the patch of the highest score s_a
minus ||x - c_a||^2 / (2 sigma^2), c_a its centre, so two patches' copies meet where
s_a - s_b = (||x - c_a||^2 - ||x - c_b||^2) / (2 sigma^2), a straight line (a power diagram of
the patch centres, which lie on a grid: the lines run along rows, columns and diagonals). Placed
at a coarse level and upsampled, a line of a few pixels becomes 2^level times longer, and the
finer passes keep it (each side's patches match their own copy). So after each pass, the
straight runs are re-cut along the path of least seam error between the two copies
(``texsynth.blocks.recut``: Efros & Freeman 2001, 2.1, with Kwatra et al. 2003, 3.1's seam
cost), as quilting cuts an overlap. Straight boundaries of 64 px or more, those whose seam error
is above the photo's mean squared neighbour difference in brackets (``benchmarks.straight_cuts``,
crop -> twice its size): brick wall 512: 21 (19) before, 5 (0) after; 1024: 51 (51), 1 (0);
setts 1024: 5 (5), 0; gravel 512: 8 (8), 0; 1024: 26 (26), 0. The re-cut takes about 1 % of the run.

Why setts came out as stubs and halves (issue 25: joints ending inside a stone, stones pieced
from two halves): the level count followed the texel (twice the correlation length,
``texsynth.blocks.period``), which on setts reads a quarter to a half of the period of a stone
and its joint, because the grain and the stones' different greys decorrelate within a stone
(``REACH_TEXELS``' figures). The largest patch at the coarsest level then covered part of a
stone (the 12 MP setts' 1024 crop: 4 levels, 16 px at level 3 = 128 px against a 330 px
period), so no level placed whole stones, and the finer patches joined pieces. Now the largest
patch spans ``REACH_TEXELS`` texels (Kwatra et al. 2005, 3: the largest patch size captures the
largest structure). Stones (``benchmarks.stones``, share of stone area in stones run together,
photo 0): the 12 MP setts' 1024 crop to 2048, 4 -> 6 levels, 1.00 -> 0.61; a 512 crop of the
2048 setts photo to 1024, 3 -> 5 levels, 0.98 -> 0.65 (median whole-stone area over the photo's
0.47 -> 1.08). The texel measure also reads a large photo sampled (as the MRF), not on a pyramid
level, whose block means drop the grain and lengthen it (the 12 MP setts: 168 px, not 312): 7
levels, where 6 already spanned a stone (merged 0.61 -> 0.65: no gain there). Brick wall,
gravel and the stochastic photos keep their level counts (and outputs);
layered or jagged rock gain two (4 -> 6, 5 -> 7: a 512 crop of layered rock to 1024, gradient
0.996 -> 1.005, seam 1.00 -> 1.03, longer layers, no new artefact seen).

Joints that stop inside elements (issue 41): told the joints' width (``joint_width``, pixels),
the exemplar gets one more channel, each pixel's signed distance to the nearest joint
(``texsynth.blocks.feature_distance``, Lefebvre & Hoppe 2006, 4), ``feature_weight`` times the
colours' standard deviation, so the patch distances, votes and alignment see where a patch lies
in its element even where its pyramid level has averaged the joint away; the output copies the
photo's pixels at the positions found. Dead-end ratio (``texsynth.metrics.dead_end_ratio``),
512 -> 1024: a 512 crop of the concrete pavers (seed 0) 2.07 without, 1.28 with (weight 4:
1.31). Held out of the tuning, seeds 0-2: the ashlar blocks 1.17, 1.15, 1.07 without, 1.07,
1.14, 1.20 with (no gain: the default already keeps them); a 512 crop of the aztec flagstones
1.00, 1.45, 0.95 without, 1.07, 2.01, 1.10 with (worse on seed 1); the 2048 granite setts'
1024 crop to 2048, seed 0, joint width 32 px: 1.38 without, 0.83 with (CPU 106 s, 104 s).
CPU time 21-27 s either way at 512 -> 1024.
(Those figures: the distance channel alone, width given.) By default (``joint_width`` 0) the
width is measured (``texsynth.blocks.joints.joint_scale``) and the distance saturated at a
joint width joins it as a second channel (``texsynth.blocks.feature_distance``); a photo
without a joint network runs the path without them, bit for bit; ``feature_weight`` 0 leaves
the joints out. Dead-end ratio by default, 512 -> 1024, seeds 0-2: the pavers' 512 crop 1.19,
1.04, 1.16; the flagstones' 512 crop 0.80, 0.97, 1.30; the ashlar blocks 1.06, 1.10, 1.21 (at
a measured width of 5.7 px, before the finest near-best scale was taken: 4 px now); the
generated wall 1.29, 1.09, 1.34 (2 px; the distance alone at 2.8 px 1.27, 1.33, 1.23). CPU 20-24
s a run under load 12 where the distance alone took 15-17 s. The repeat peak beyond 24 px
rose on the pavers' seed 1 to 0.41 (the photo's own 0.24; 0.34 with the distance alone).

Where a whole region comes out twice (issue 41, open: a 256 crop of the rock face, box-averaged
by 2, to 512, seed 0: the autocorrelation's peak beyond 24 px 0.30 against the photo's 0.13, at
a shift of (184, -216)): the share of pixels whose exemplar pixel recurs at that shift, read on
the position map after each step, is 0.08 after the coarsest level's largest patch (exemplar 32
px across, output 64, where two copies of 721 and 562 px cover more than the exemplar's 1024),
0.13 after its smaller patch, 0.14 after the alignment, and the finer levels keep it (0.15): the
double copy forms at the coarsest level, in the EM's growth, not in the finer levels. Tried and
left out: the usage term also charging each large copy (runs of grid patches whose sources
advance with them, from a sixteenth to a quarter of the exemplar's area) beyond the first; it
took the peaks, rock seeds 0-3, from 0.30, 0.29, 0.36, 0.25 to 0.09, 0.09, 0.10, 0.13, but the
outputs became wide fields of the photo's one flat grey patch (the charge falls on every copy,
so the smooth patch that matches anywhere wins).
Fixed by the level count: at that level the exemplar holds only 17^2 patches of 16 px, and
they must cover four times its area. On a photo without a joint network the automatic count
now stops where the coarsest exemplar spans ``COARSEST_PATCHES`` (4) largest patches (the rock:
4 -> 3 levels): repetition peak, seeds 0-2, 0.30, 0.29, 0.36 -> 0.11, 0.12, 0.10 (photo 0.13),
gradient ratio 1.001, 1.014, 0.990 -> 1.000, 0.996, 0.979; a 512 crop of the layered rock to
1024, seed 0, 6 -> 4 levels: the photo laid 2 x 2 side by side before, peak 0.48 -> 0.10
(photo 0.18), gradient 1.005 -> 0.996, shorter layers. Also tried and left out: re-drawing
the smaller copy behind the coarsest level's strongest recurrence from random pixels and
running the level again (twice): the EM grew another double copy (share 0.07 -> 0.07, peaks
0.35, 0.23, 0.28). The cap on photos with joints cost whole elements (dead-end ratio, 512 ->
1024, seeds 0-2, one level or two fewer): pavers 1.19, 1.04, 1.16 -> 1.23, 1.28, 1.38 (the
repeat peak 0.22-0.41 -> 0.20-0.22), generated wall 1.29, 1.09, 1.34 -> 1.43, 1.37, 1.43,
flagstones 0.80, 0.97, 1.30 -> 1.40, 1.20, 1.47, setts 2.15, 1.62, 2.76 -> 1.89, 2.25, 1.73;
so there the coarsest exemplar spans two largest patches (32 px), one before: the pavers' 512
crop 6 -> 5 levels, dead ends 1.19, 1.04, 1.16 -> 1.08, 1.20, 1.15 and its repeat peak (beyond
24 px) 0.22-0.41 -> 0.22-0.26 (photo 0.24); the brick wall's crop 6 -> 5, 1.09, 1.01, 1.04;
the ashlar blocks 6 -> 5, 1.06, 1.10, 1.21 -> 1.10, 1.00, 1.10; the generated wall,
flagstones and setts keep 5 (the wall at 4: 1.31, 1.31, 1.35). The repetition section's brick
256 crop to 512, seed 0: peak 0.43 -> 0.41 (photo 0.33).

Joints that stopped where copies met half a course apart (issue 41, the generated wall's seeds
0-2: 1.29, 1.09, 1.34): on a photo with joints laid in courses (``texsynth.blocks.rhythm``'s
course period), the alignment after each coarse level first places the copies breadth first
from the largest (``align_regions``' walk, as ``multiscale_mrf``), so a group of copies in
phase with each other but not with the rest follows its first. Dead-end ratio, 512 -> 1024,
seeds 0-2 (``benchmarks.sections.elements``' methods): generated wall 1.12, 1.25, 1.12; brick
wall's crop 1.01-1.09 -> 0.97, 0.94, 1.05; pavers' crop 1.08-1.20 -> 1.24, 1.23, 1.18 (repeat
peak 0.21-0.22, photo 0.24). Flagstones, ashlar and setts have no course period (unchanged:
the walk on them gave flagstones seed 0 1.40, setts 1.83-2.68 against 1.41-2.45 before).
Where the photo repeats along its courses' lattice (``texsynth.blocks.rhythm.lattice``, as
``multiscale_mrf``: of the benchmark's photos the generated wall only), the aligned levels with
at least ``LOCK_STEPS`` pixels a course then lock the copies into one phase of it, broken once
along a row (``region_shift.lock_lattice``: the wall's output is 37 1/3 courses high). The
generated wall, seeds 0-5, before / after: 1.14, 1.26, 1.12, 1.25, 1.14, 1.16 / 1.09, 1.19,
1.10, 1.16, 1.00, 1.08, its courses straight across the wrap, one sliver course; gradient ratio
1.00 / 1.01, repeat peak 0.54 both (photo 0.55); CPU 12.9 / 14.4 s (one run each, under load).

Where the pavers' joints still stopped (issue 41, the pavers' 512 crop over 1.25 on seeds 0-1
and 4; ``multiscale_mrf``'s cost, ours): of seed 4's 130 dead ends (0's 123) 83 (100) lay
inside a copy and 79 (96) of those on a copy of one of the photo's own 20 (at most 7 px from
it), 47 (23) at a seam. So where there are joints, an exemplar patch whose block, grown by
``DEAD_END_MARGIN`` joint half widths, holds one of the photo's dead ends (read as
``texsynth.metrics.dead_end_ratio`` reads the photo, with the joints the method measured)
costs ``DEAD_END_COST`` times the iteration's mean matching distance more, beside the usage
term (the median, which scales the usage term, is 0 at levels 0-1: most patches there are
copied exactly). Only at the levels and patch sizes where at most ``DEAD_END_SHARE`` of the
patches hold one (on the pavers levels 0-1 and level 2's 8 px patch; at 0.46 on level 2's
16 px patch, the cost at 8 on levels 0-2 took seeds 0-5 to 0.77-1.11 but laid the pavers out
anew, courses in stairs and short pavers where the copies dodged the stubs; levels 0-1 at 4:
1.25, 1.21 on seeds 4, 0). Dead-end ratio, each photo to twice its size (the elements
section's methods), seeds 0-2, before / after: pavers' 512 crop 1.25, 1.25, 1.18 / 0.79,
0.81, 0.72 (seeds 3-5 1.16, 1.34, 1.08 / 0.76, 0.77, 0.82: fewer stubs, the layout kept);
brick wall's crop 0.97, 0.93, 1.02 / 0.93, 0.90, 0.96; generated wall 1.09, 1.19, 1.10 /
0.94, 1.04, 0.92; ashlar 1.09, 1.00, 1.10 / 0.88, 0.87, 0.83; flagstones 0.79, 0.95, 1.21 /
0.83, 0.73, 1.31 (6 dead ends in its photo: a seed reads within about 20 %; seed 2's picture
alike, its stubs where they were); setts reduced 1.06, 1.01, 0.96 / 0.84, 0.75, 0.70; gravel
(no joints: the path without the cost) 0.01. Gradient ratio after 1.00-1.07, repeat peak
within the photo's own + 0.03 (ashlar 0.34 on seed 2, photo 0.33).

At 16 the flagstones' seed 2 read 1.31 (32 dead ends on 18408 px; main's seed 5 1.30, 31 on
17958; seeds 0-5 main 0.79-1.30, at 16 0.72-1.31). The photo's 6 ends are all the ridges' gaps
where three joints meet, not broken joints; of seed 2's 32 about 19 were such gaps at junctions
whole in the picture, 10 of them copies of the photo's own (7 inside a copy, 3 at a seam: the
cost at 16 did not keep them out), and about 13 real stubs or offsets, 11 at seams.
``DEAD_END_COST`` 64 (the share still keeps it off the coarse levels, so the layouts are kept:
courses straight, no stairs), seeds 0-2: pavers 0.65, 0.75, 0.46 (seeds 3-5 0.70, 0.88, 0.83);
brick wall's crop 0.72, 0.68, 0.65; generated wall 0.79, 0.91, 0.77; ashlar 0.66, 0.60, 0.65;
flagstones 0.50, 0.87, 1.04 (seeds 3-5 0.64, 0.91, 0.75); setts reduced 0.62, 0.58, 0.51;
gravel as it was (no joints, no cost). Gradient ratio 0.98-1.07, repeat peak at most the
photo's own + 0.01 (ashlar 0.34, photo 0.33); CPU as at 16 (flagstones' seed 3 A/B, under load:
21.3, 23.4 / 23.4, 23.0 s). The running bond's test stubs: 0.64 of a pixel's copies (1.25 at
16, 1.31 without). On the flagstones' seed 2 (25 ends) the gaps at junctions went from about 19
to 12, the real stubs from about 13 to 10; stubs made at seams stay (three at its crossing).

Deviations, one line each:
- the feature distance and its saturation are two more exemplar channels (Lefebvre & Hoppe:
  the distance, after a PCA);
- the nearest-patch distance is taken on short patch descriptors (``PatchFeatures``);
- usage counts are refreshed once per EM iteration, not per PatchMatch step;
- each level and patch size ends with a non-averaged pass (Kaspar et al. 2015, 5): each pixel
  is the pixel of its best overlapping patch, the highest IRLS weight (usage term included)
  times a Gaussian falloff from the patch centre (sigma a grid step), not the weighted average:
  crisp, and the position map (so every map of a material can follow);
- ``levels`` 0 (the default) takes enough levels for the largest patch to span
  ``REACH_TEXELS`` texels (``texsynth.blocks.period``), at least 3, no more than leave
  ``COARSEST_PATCHES`` of them across the coarsest exemplar; the coarse
  levels (2 and up) run ``COARSE`` times the EM iterations;
- on an exemplar of more than ``SOURCES`` pixels, a level searches only the patches on a
  lattice of spacing ``_stride`` (a power of two, at most the grid step p/4, so propagation
  stays on it; every exemplar pixel still lies in a lattice patch);
- output neighbourhoods wrap around the output (it tiles); exemplar patches lie inside it;
- after each level but the finest, each verbatim copy may move by up to ``SHIFT`` pixels each
  way where that joins its seams (``align_regions``), ours, after Pritch et al. 2009's shift-map;
- (ours) where the courses' lattice repeats, the aligned levels lock the copies into one phase
  of it (``lock_lattice``), the phase broken once along a row and a column where asked;
- (ours) where there are joints, the exemplar patches that hold one of the photo's own dead
  ends cost more (``DEAD_END_COST``), where few patches hold one (``DEAD_END_SHARE``);
- after each level and patch size, boundaries straight for ``RUN`` pixels are re-cut within
  ``BAND`` pixels of their line (``recut_straight``), not every boundary by a graph cut.

References
----------
Kwatra et al. 2005, section 3; Barnes et al. 2009; Kaspar et al. 2015, sections 4-5;
Efros & Freeman 2001, section 2.1; Kwatra et al. 2003, section 3.1; Pritch, Kav-Venaki
& Peleg 2009.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import maximum_filter, uniform_filter

from ..blocks import feature_distance, joint_repair
from ..blocks.joints import luma
from ..blocks.patchmatch import (
    BLOCK_ROWS,
    CELLS,
    CHUNK,
    DIMS,
    FIT_SAMPLES,
    PatchFeatures,
    patchmatch,
)
from ..blocks.period import texel_size
from ..blocks.recut import recut_straight
from ..blocks.region_shift import align_regions, lock_lattice
from ..blocks.rhythm import course_period
from ..blocks.rhythm import lattice as course_lattice
from ..registry import Method, Param, register

__all__ = ["texture_optimization", "optimize", "level_count", "METHOD"]

#: Kwatra et al.'s robust exponent r.
R = 0.8
#: PatchMatch iterations per EM iteration.
MATCH_ITERATIONS = 2
#: Exemplar patches a level's search table holds before they are taken on a lattice.
SOURCES = 1 << 21
#: Memory model (bytes an output pixel, and per channel) and cost model (reference seconds an
#: output pixel at two sizes, a search table's lattice point, and a pixel of a level whose
#: copies are aligned): see ``_memory``, ``_cost``.
MEM_OUT, MEM_OUT_C = 100, 16
MEM_SEARCH, SEARCH_PIXELS = 620, 1 << 18
#: Output pixels of the runs the time's coefficients were fitted on (2048 x 2048); smaller
#: outputs take less per pixel, as (pixels / FIT_PIXELS)^0.12 (issue 45: 64 -> 256 and
#: 32 -> 512, quiet 1.08 and 2.63 s, had been told 1.0 and 1.6 times that at the reference's
#: speed), beside 1.2 s of fixed work (the joints' measure, the levels' set-up).
FIT_PIXELS = 2048 * 2048
COST_OUT, COST_TABLE, COST_ALIGN = 4.7e-5, 1.46e-5, 8e-6
#: The work that does not grow with the channels (the descriptors' ``DIMS`` components, the
#: matches), in channels' worth: the joints' two channels (5 against 3) cost 1.09-1.28x, median
#: 1.19 (the elements section's CPU column, 512 -> 1024, six photos), where c / 3 told 1.67x and
#: the predictions' 32 -> 512 from the pool_water corner (joints 2 px) 1.47x its time.
CHANNEL_BASE = 7.5
#: EM iterations at the coarse levels (2 and up, a sixteenth of the work or less), times
#: ``iterations``: there the layout (rows, joints) is decided.
COARSE = 2
#: The progress's model of a step (issue 40; least squares on the CPU seconds of each level's
#: and patch size's EM iterations and alignment, medians of 8 runs of 128 -> 256 and 256 -> 512
#: on the brick, 14 steps within 0.87-1.21 of it, the former model's 0.81-1.42, its 512^2
#: patch-8 step 1.42): per EM iteration, STEP_PATCH s a patch-grid point (the grid has
#: (p_min / p)^2 of p_min's points), STEP_PIXEL s a pixel, both times (pixels / FIT_PIXELS)^0.12
#: as in the time's model, and STEP_FIXED s; the copies' alignment ALIGN_FIXED + ALIGN_PIXEL s
#: a pixel, its own span (it had been reported at the step's end: no progress for 2-3 % of the
#: time). Refitted with 128 -> 512 (issue 40: relative least squares on the CPU medians of 2
#: runs each of 128 -> 256, 256 -> 512, 128 -> 512, scaled to the former's seconds: 20 steps
#: within 0.79-1.29 of their median, the former 0.41-0.87 of theirs, at 90 % of 128 -> 512
#: read 0.41; the alignment had been given a third of its time).
STEP_PATCH, STEP_PIXEL, STEP_FIXED = 1.9e-6, 1.0e-6, 0.003
#: Within a step, in its EM iterations' time: the search table's build before the first
#: (BUILD) and the final pass after the last (FINAL). CPU medians of 3 at 128 -> 256 and
#: 256 -> 512, the finest two levels: the build and first iteration 0.44-0.56 of a 3-iteration
#: step, the last two 0.20-0.26 each, the final pass 0.03-0.09; equal thirds and the final pass
#: at the step's end had told the first third too fast and the end too slow (0.75 at 90 %).
BUILD, FINAL = 1.0, 0.25
ALIGN_FIXED, ALIGN_PIXEL = 0.004, 4.6e-6
#: The joints' measure and the courses' period before the levels, in the same seconds:
#: SETUP_FIXED + SETUP_PIXEL an exemplar pixel, at most SETUP_MAX (it samples a large photo;
#: CPU medians of 3 on the brick 128^2, 256^2: 0.020, 0.063 s; the gravel 128^2 to 2048^2:
#: 0.016, 0.051, 0.18, 0.28, 0.28 s); the progress had started after it (2.5 % of 128 -> 256
#: at fraction 0: 1.3x told at 10 %).
SETUP_FIXED, SETUP_PIXEL, SETUP_MAX = 0.005, 7.5e-7, 0.28
#: Texels the coarsest (largest) patch spans: the texel (twice the correlation length) reads a
#: quarter to a half of the setts' period, stone and joint (512 crop of the 2048 setts photo:
#: 40 px against 170; the 12 MP setts' 1024 crop: 86 against 336; the 12 MP setts: 168 / 344).
REACH_TEXELS = 4
#: The fewest levels the automatic choice gives (the former default).
MIN_LEVELS = 3
#: Largest patches the coarsest exemplar spans at least, in the automatic choice above
#: ``MIN_LEVELS``, on a photo without joints and with (issue 41): at two without (a 32 px
#: exemplar, 17^2 patches of 16 px) its few patches cover an output of four times its area
#: in a few large copies, two of one region; with joints, one (16 px) did the same on the
#: pavers, four broke elements.
COARSEST_PATCHES = (4, 2)
#: The largest move (pixels per axis, at the level) of a copied region after a coarse level.
SHIFT = 3
#: Where the photo repeats along its courses' lattice (``rhythm.lattice``: correlation at least
#: ``LOCK_REPEAT`` along each period vector), the aligned levels with at least ``LOCK_STEPS``
#: pixels a course lock their copies into one phase of it (``multiscale_mrf``'s figures).
LOCK_REPEAT, LOCK_STEPS = 0.35, 2
#: The feature-distance channel's standard deviation, in the colours' (``feature_distance``).
FEATURE_WEIGHT = 2.0
#: Where there are joints, the exemplar patches whose block (grown by ``DEAD_END_MARGIN`` joint
#: half widths) holds one of the photo's own dead ends cost ``DEAD_END_COST`` times the median
#: mean matching distance more, at the levels and patch sizes where at most ``DEAD_END_SHARE``
#: of the patches hold one (where most do, the cost would lay the elements out anew).
DEAD_END_COST, DEAD_END_MARGIN, DEAD_END_SHARE = 64.0, 2.0, 0.25
#: The shortest straight cut between copies re-cut, and how far its new path may wander
#: (pixels at the level).
RUN, BAND = 16, 8


def level_count(exemplar_shape, width, height, patch_size, levels) -> int:
    """``levels`` capped so the coarsest exemplar holds two smallest patches and the coarsest
    output one."""
    n = 1
    while (n < levels and min(exemplar_shape[:2]) >> n >= 2 * patch_size
           and min(width, height) >> n >= patch_size):
        n += 1
    return n


def _auto_levels(exemplar, patch, elements=False):
    """Levels enough for the coarsest (largest) patch, ``patch`` 2^(L-1) pixels across, to span
    ``REACH_TEXELS`` of the exemplar's texels (``texsynth.blocks.period``, which samples a large
    photo), but no more than leave the coarsest exemplar ``COARSEST_PATCHES`` such patches
    across (the nearest power of two; the second figure on a photo with ``elements``, a joint
    network); at least ``MIN_LEVELS``."""
    texel = texel_size(exemplar)
    reach = 1 + int(np.ceil(np.log2(max(1.0, REACH_TEXELS * texel / patch))))
    across = min(exemplar.shape[:2]) / (COARSEST_PATCHES[bool(elements)] * patch)
    room = 1 + int(np.round(np.log2(max(1.0, across))))
    return max(MIN_LEVELS, min(reach, room))


def _stride(shape, p) -> int:
    """The lattice spacing of the exemplar patches searched at patch size ``p``: 1, or for an
    exemplar of more than ``SOURCES`` pixels the power of two that brings it under, at most the
    output grid step p / 4 (propagation's offsets then stay on the lattice)."""
    s = 1
    while (shape[0] // s) * (shape[1] // s) > SOURCES and 2 * s <= p // 4:
        s *= 2
    return s


def _downsample(image):
    """2 x 2 block means (an odd last row or column dropped)."""
    h, w = image.shape[0] // 2 * 2, image.shape[1] // 2 * 2
    a = image[:h, :w]
    return 0.25 * (a[0::2, 0::2] + a[1::2, 0::2] + a[0::2, 1::2] + a[1::2, 1::2])


def optimize(exemplar, height, width, rng, progress, levels=0, patch_size=8, sizes=2,
             iterations=3, uniformity=2.0, elements=False, courses=False, setup=0.0,
             lattice=None, joints=None):
    """Texture optimisation of a (height, width) periodic output; returns (image, positions).
    ``levels`` 0: enough to span the exemplar's texel (see the module notes); ``elements``:
    the exemplar has a joint network (its channels added), whose elements the coarsest levels
    place whole; ``courses``: its elements are laid in courses, and the alignment places the
    copies breadth first from the largest (``align_regions``' walk); ``setup``: the seconds
    (``_step_cost``'s) of the caller's work before, done when the progress reaches its share;
    ``lattice``: the courses' (P, Q, s) the copies lock into after their alignment, on the
    levels that divide it into at least ``LOCK_STEPS`` pixels a course (``lock_lattice``);
    ``joints``: (the photo's luma, the ``Joints`` read on it), whose dead ends cost the patches
    that hold them where few patches do (``_stubs``, ``DEAD_END_SHARE``).
    """
    progress(0.0, "analysing the exemplar")
    if levels == 0:
        levels = _auto_levels(exemplar, patch_size << (sizes - 1), elements)
    n_levels = level_count(exemplar.shape, width, height, patch_size, levels)
    pyramid = [exemplar]  # built once, to the levels used
    for _ in range(n_levels - 1):
        pyramid.append(_downsample(pyramid[-1]))
    steps = [(lv, p) for lv in reversed(range(n_levels))
             for p in (patch_size << k for k in reversed(range(sizes)))
             if p <= min(pyramid[lv].shape[:2]) // 2 or p == patch_size]
    # spans[2 i], spans[2 i + 1], spans[2 i + 2]: step i's EM iterations, then its alignment
    spans = np.cumsum([setup] + [c for lv, p in steps
                               for c in _step_cost(height, width, lv, p, patch_size, iterations)])
    spans /= spans[-1]
    ends = None if joints is None else joint_repair.photo_ends(*joints)
    positions = None
    for i, (lv, p) in enumerate(steps):
        z = pyramid[lv]
        shape = (-(-height // 2 ** lv), -(-width // 2 ** lv))
        if positions is not None and positions.shape[:2] != shape:
            positions = _upsample(positions, shape, z.shape)
        start, relaxed, stop = spans[2 * i:2 * i + 3]
        stubs = None if ends is None else \
            _stubs(ends, lv, p, _stride(z.shape, p), z.shape[:2], joints[1].sigma)
        if stubs is not None and stubs.mean() > DEAD_END_SHARE:
            stubs = None
        positions = _optimize_size(z, shape, p, positions, rng,
                                   iterations * (COARSE if lv >= 2 else 1), uniformity,
                                   progress.span(start, relaxed), f"level {lv}, patch {p}",
                                   stubs)
        label = f"level {lv}: re-cutting straight cuts"
        positions = recut_straight(z, positions, RUN, BAND,
                                   tick=lambda d=relaxed, m=label: progress(d, m))
        if lv >= 1:  # the copies slide into phase while their layout is still coarse
            label = f"level {lv}: aligning copies"
            aligning = progress.span(relaxed, stop)
            positions = align_regions(z, positions, SHIFT,
                                      tick=lambda d, m=label, a=aligning: a(d, m),
                                      walk=courses)
            if (lattice is not None and not any(v % 2 ** lv for v in lattice)
                    and lattice[0] >> lv >= LOCK_STEPS):
                positions = lock_lattice(luma(z[:, :, :3]), positions,
                                         tuple(v >> lv for v in lattice))
    return exemplar[positions[:, :, 0], positions[:, :, 1]], positions


def _stubs(ends, lv, p, s, shape, sigma):
    """The exemplar patches (bool, on the search lattice of spacing ``s``: ``PatchFeatures``'
    shape) of side ``p`` at level ``lv`` (exemplar ``shape``) whose block, grown by
    ``DEAD_END_MARGIN`` joint half widths ``sigma`` (full-resolution pixels), holds one of the
    photo's dead ends ``ends`` (full resolution)."""
    step = 2 ** lv
    h, w = shape
    at = ends[:h * step, :w * step].reshape(h, step, w, step).any(axis=(1, 3))
    m = int(np.ceil(DEAD_END_MARGIN * sigma / step))
    size = p + 2 * m
    near = maximum_filter(at, size, origin=m - size // 2, mode="constant")
    return near[:h - p + 1:s, :w - p + 1:s]


def _step_cost(height, width, lv, p, p_min, iterations) -> tuple[float, float]:
    """(EM iterations, alignment) seconds of one level and patch size in the progress's model
    (``STEP_PATCH``, ``STEP_PIXEL``, ``STEP_FIXED``, ``ALIGN_FIXED``, ``ALIGN_PIXEL``): each
    step's share of the progress, which equal shares had told at a third to a quarter of the
    time (the finest level's steps hold most of it at 1024 -> 2048)."""
    pixels = -(-height // 2 ** lv) * -(-width // 2 ** lv)
    work = iterations * (COARSE if lv >= 2 else 1)
    scale = (pixels / FIT_PIXELS) ** 0.12
    relax = work * ((STEP_PATCH * (p_min / p) ** 2 + STEP_PIXEL) * scale * pixels + STEP_FIXED)
    return relax, (ALIGN_FIXED + ALIGN_PIXEL * pixels if lv >= 1 else 0.0)


def _upsample(positions, shape, exemplar_shape):
    """Positions of a level twice as fine: each pixel's child keeps its offset in the block."""
    i = np.arange(shape[0])[:, None]
    j = np.arange(shape[1])[None, :]
    coarse = positions[i // 2, j // 2]
    out = np.empty(shape + (2,), np.int32)
    out[:, :, 0] = np.minimum(2 * coarse[:, :, 0] + i % 2, exemplar_shape[0] - 1)
    out[:, :, 1] = np.minimum(2 * coarse[:, :, 1] + j % 2, exemplar_shape[1] - 1)
    return out


class _Grid:
    """Kwatra's output neighbourhoods: p x p patches with top-left corners every p/4 pixels,
    wrapping around the (H, W) output."""

    def __init__(self, shape, p):
        self.shape, self.p = shape, p
        step = max(1, p // 4)
        self.rows = np.arange(0, shape[0], step)
        self.cols = np.arange(0, shape[1], step)
        gi, gj = np.indices((len(self.rows), len(self.cols))).reshape(2, -1)
        self.top, self.left = self.rows[gi], self.cols[gj]
        self.index = (gi, gj)

    def offsets(self):
        """Per patch pixel (u, v): the output pixels (flat) of the patches."""
        hh, ww = self.shape
        for u in range(self.p):
            r = ((self.top + u) % hh) * ww
            for v in range(self.p):
                yield u, v, r + (self.left + v) % ww


def _vote(z, nnf, weights, grid, tick):
    """E-step: the weighted average of the overlapping exemplar patches on every pixel.
    Summed one patch pixel (u, v) at a time: the patches then cover distinct output
    pixels, so each sum is a plain indexed add and no temporary grows with p^2."""
    hh, ww = grid.shape
    c = z.shape[2]
    flat_z = z.reshape(-1, c)
    sr, sc = nnf[grid.index][:, 0], nnf[grid.index][:, 1]
    wgt = weights.astype(np.float64)
    norm = np.zeros(hh * ww)
    total = np.zeros((hh * ww, c))
    for u, v, target in grid.offsets():
        norm[target] += wgt
        total[target] += wgt[:, None] * flat_z[(sr + u) * z.shape[1] + sc + v]
        tick()
    covered = norm > 0
    image = np.zeros((hh * ww, c), np.float32)
    for s in range(0, hh * ww, CHUNK):
        sl = slice(s, s + CHUNK)
        done = covered[sl]
        image[sl][done] = total[sl][done] / norm[sl][done, None]
        tick()
    return image.reshape(hh, ww, c)


def _collage(z, nnf, score, grid, positions, tick):
    """E-step without averaging: each pixel takes the exemplar pixel voted by its best
    overlapping patch, the one of highest ``score`` (log IRLS weight) plus a Gaussian falloff
    from the patch centre (Kaspar et al. 2015, 5: sigma a grid step); ``tick()`` after each
    patch pixel (u, v). Returns the new positions."""
    hh, ww = grid.shape
    sr, sc = nnf[grid.index][:, 0], nnf[grid.index][:, 1]
    centre = (grid.p - 1) / 2
    sigma = max(1, grid.p // 4)
    best = np.full(hh * ww, -np.inf, np.float32)
    source = np.zeros(hh * ww, np.int64)
    for u, v, target in grid.offsets():
        s = (sr + u) * z.shape[1] + sc + v
        here = score - np.float32(((u - centre) ** 2 + (v - centre) ** 2) / (2 * sigma ** 2))
        better = here > best[target]
        best[target[better]] = here[better]
        source[target[better]] = s[better]
        tick()
    covered = np.isfinite(best).reshape(hh, ww)
    out = positions.copy()
    r, col = np.divmod(source.reshape(hh, ww), z.shape[1])
    out[:, :, 0] = np.where(covered, r, out[:, :, 0])
    out[:, :, 1] = np.where(covered, col, out[:, :, 1])
    return out


def _usage_penalty(nnf, grid, features, cost, uniformity):
    """Kaspar et al.'s occurrence term: uses of the exemplar patches near each patch z (a box of
    the grid step), over the uniform usage, beyond 1, times lambda and the median distance; on
    the lattice of ``features``."""
    hs, ws = features.shape
    s = features.stride
    step = max(1, grid.p // 4 // s)
    flat = nnf[grid.index][:, 0] // s * ws + nnf[grid.index][:, 1] // s
    uses = np.bincount(flat, minlength=hs * ws).reshape(hs, ws).astype(np.float32)
    near = uniform_filter(uses, size=step, mode="constant") * step * step
    uniform = max(1.0, len(flat) * step * step / (hs * ws))
    scale = uniformity * float(np.median(cost))
    return (scale * np.maximum(0.0, near / uniform - 1.0)).astype(np.float32)


def _optimize_size(z, shape, p, positions, rng, iterations, uniformity, progress, label,
                   stubs=None):
    """Kwatra's EM iterations at one level and patch size; returns the new positions.
    ``stubs`` (bool, on the search lattice): the patches that hold one of the photo's dead
    ends, which cost ``DEAD_END_COST`` median distances more (from the second iteration)."""
    progress(0.0, label)
    features = PatchFeatures(z, p, rng, tick=lambda: progress(0.0, label),
                             stride=_stride(z.shape, p))
    hs, ws = features.shape
    s = features.stride
    grid = _Grid(shape, p)
    if positions is None:  # Kwatra's start: random exemplar patches, side by side
        i = np.arange(shape[0])[:, None]
        j = np.arange(shape[1])[None, :]
        corner_r = s * rng.integers(0, hs, (-(-shape[0] // p), -(-shape[1] // p)))
        corner_c = s * rng.integers(0, ws, corner_r.shape)
        positions = np.stack([corner_r[i // p, j // p] + i % p, corner_c[i // p, j // p] + j % p],
                             axis=2).astype(np.int32)
    nnf = positions[np.ix_(grid.rows, grid.cols)].copy()
    nnf[:, :, 0] = np.minimum(nnf[:, :, 0] // s, hs - 1) * s
    nnf[:, :, 1] = np.minimum(nnf[:, :, 1] // s, ws - 1) * s
    image = z[positions[:, :, 0], positions[:, :, 1]]
    penalty = None
    # The progress by the ticks (blocks of rows, chunks of patches), the iterations' work:
    # after the table's build and the first iteration, the others share the rest by its
    # count, the last without its vote's (equal shares had told 88 % done with a tenth of the
    # time left, then nothing more); then the final pass (``BUILD``, ``FINAL``).
    count = {"ticks": 0, "first": 0, "rest": 0}
    whole = BUILD + iterations + FINAL

    def tick():
        """Between the steps of an iteration: Esc is heard, and the progress moves."""
        count["ticks"] += 1
        done = (count["ticks"] - count["first"]) / count["rest"] if count["rest"] else 0.0
        progress((BUILD + 1 + min(done, 1.0) * (iterations - 1)) / whole if count["rest"]
                 else 0.0, label)

    for it in range(iterations):
        tick()
        target = features.describe(image, grid.top, grid.left, tick)
        total = patchmatch(features, target, nnf, grid.rows, grid.cols, shape, rng,
                           MATCH_ITERATIONS, grid.index, penalty, tick)
        cost = total if penalty is None else \
            total - penalty[nnf[grid.index][:, 0] // s, nnf[grid.index][:, 1] // s]
        if uniformity > 0 or stubs is not None:
            penalty = np.zeros(features.shape, np.float32) if uniformity <= 0 else \
                _usage_penalty(nnf, grid, features, cost, uniformity)
            if stubs is not None:
                penalty += np.float32(DEAD_END_COST * np.mean(cost)) * stubs
            tick()
        eps = 1e-3 * float(np.mean(cost)) + 1e-12
        if it < iterations - 1:
            before = count["ticks"]
            weights = (np.maximum(cost, 0) + eps) ** ((R - 2) / 2)
            image = _vote(z, nnf, weights.astype(np.float32), grid, tick)
            if it == 0:  # the next iterations: as many ticks each, the last without a vote
                count["first"] = count["ticks"]
                count["rest"] = max(count["first"] * (iterations - 1) - (count["ticks"] - before),
                                    1)
    if penalty is not None:  # the final pass sees the usage of the last matches
        total = cost + penalty[nnf[grid.index][:, 0] // s, nnf[grid.index][:, 1] // s]
    score = ((R - 2) / 2 * np.log(np.maximum(total, 0) + eps)).astype(np.float32)
    offsets = [0]

    def final_tick():
        offsets[0] += 1
        progress((BUILD + iterations + FINAL * offsets[0] / p ** 2) / whole, label)

    return _collage(z, nnf, score, grid, positions, final_tick)


def texture_optimization(exemplar, width, height, rng, progress, levels=0, patch_size=8,
                         sizes=2, iterations=3, uniformity=2.0, joint_width=0.0,
                         feature_weight=FEATURE_WEIGHT):
    """Minimise the texture energy of (height, width, C) by EM over PatchMatch's nearest exemplar
    patches, coarse to fine, with its position map (see the module notes).

    Parameters
    ----------
    exemplar : float32 array (H, W, C)
        The sample, validated by ``texsynth.synthesize``.
    width, height : int
        The output size, larger or smaller than the exemplar.
    rng, progress : numpy.random.Generator, texsynth.progress.Progress
        The seeded generator and the progress reporter ``texsynth.synthesize`` makes.
    levels : int
        Resolution levels, coarse to fine (capped by the exemplar and output sizes); 0: enough
        for the largest patch at the coarsest level to span the exemplar's texels.
    patch_size : int
        Smallest patch side (pixels); each level also runs the larger sizes first.
    sizes : int
        Patch sizes per level, each twice the next, large to small.
    iterations : int
        EM iterations per level and patch size.
    uniformity : float
        Weight lambda of the uniform patch usage term (0: off): higher repeats fewer favourite
        patches.
    joint_width : float
        The joints' width in pixels on a man-made surface (bricks, blocks, setts): the
        patches also compare the signed distance to the nearest joint (Lefebvre & Hoppe 2006,
        4); 0 (the default) measures it (``texsynth.blocks.joints.joint_scale``), and a photo
        without a joint network (gravel, rock) is synthesized without the channel.
    feature_weight : float
        That channel's weight, in units of the colours' standard deviation; 0 leaves it out.

    Returns
    -------
    image : numpy.ndarray
        float32 (height, width, C), periodic; the last pass copies whole pixels.
    positions : numpy.ndarray
        int32 (height, width, 2), the (row, col) of the exemplar pixel each one shows.

    References
    ----------
    Kwatra et al. 2005, section 3 (the texture energy, its EM); Barnes et al. 2009 (PatchMatch);
    Kaspar et al. 2015, sections 4-5 (uniform patch usage, patch sizes, the non-averaged pass);
    Efros & Freeman 2001, 2.1 and Kwatra et al. 2003, 3.1 (straight cuts re-cut); Pritch,
    Kav-Venaki & Peleg 2009 (copies aligned); Lefebvre & Hoppe 2006, 4 (the feature-distance
    channel).

    Examples
    --------
    >>> import numpy as np, texsynth
    >>> photo = np.random.default_rng(0).random((32, 32, 3), dtype=np.float32)
    >>> image, positions = texsynth.synthesize_positions(photo, 32, 32,
    ...                                                  method="texture_optimization", seed=1,
    ...                                                  iterations=1)
    >>> image.shape, np.array_equal(texsynth.apply_positions(positions, photo), image)
    ((32, 32, 3), True)
    """
    if min(exemplar.shape[:2]) < patch_size:
        raise ValueError(f"the exemplar ({exemplar.shape[1]} x {exemplar.shape[0]}) is smaller "
                         f"than the patch ({patch_size} x {patch_size}); use a smaller patch size "
                         "or a larger exemplar")
    if min(width, height) < patch_size:
        raise ValueError(f"the output ({width} x {height}) is smaller than the patch "
                         f"({patch_size} x {patch_size}); use a smaller patch size")
    joints = feature_distance.fit(exemplar, joint_width, feature_weight)
    work = exemplar if joints is None else feature_distance.augment(exemplar, joint_width,
                                                                    feature_weight, joints)
    elements = work is not exemplar
    courses = elements and course_period(exemplar) is not None
    lattice = course_lattice(exemplar, LOCK_REPEAT) if courses else None
    setup = min(SETUP_FIXED + SETUP_PIXEL * exemplar.shape[0] * exemplar.shape[1], SETUP_MAX)
    out, positions = optimize(work, height, width, rng, progress, levels, patch_size, sizes,
                              iterations, uniformity, elements, courses, setup, lattice,
                              (luma(exemplar), joints) if elements else None)
    if work is exemplar:
        return out, positions
    return exemplar[positions[:, :, 0], positions[:, :, 1]], positions


def _tables(shape, params):
    """(rows, cols) of the finest level's search table at each patch size (``stride``)."""
    h, w = shape[:2]
    sizes = [params["patch_size"] << k for k in range(params["sizes"])]
    return [(max(0, h - p) // _stride((h, w), p) + 1, max(0, w - p) // _stride((h, w), p) + 1)
            for p in sizes]


def _memory(shape, width, height, params):
    """The finest level's search table at the smallest patch (DIMS floats a lattice point) and
    its build (a block of ``BLOCK_ROWS`` lattice rows' cell means, and the principal
    components' samples in float64, twice); the exemplar, its pyramid and cell means (about
    three copies); per output pixel: positions, image, vote sums,
    the final pass's choices and the grid's share (a patch every 4 pixels at the smallest size:
    descriptors, matches, costs, candidates), measured as VmHWM at 1024 -> 2048 and
    12 MP -> 2048; tests/test_contract.py holds the estimate above the peak. Plus the
    searches' working set, which grows with the output up to a cap: ``MEM_SEARCH`` bytes for
    each of the first ``SEARCH_PIXELS`` output pixels (issue 45: from a 32^2 exemplar, traced
    19, 72 and 91 MiB beyond the rest at 256^2, 512^2 and 1024^2, resident 1.2-1.5x that;
    without it the model read 0.24-0.43 of the resident peak there; at 350 bytes, 0.50-0.59 of
    the resident at 64 -> 256, 2048 x 32 and 32 -> 512: 71, 71 and 255 MiB; 128 -> 256 peaks
    at 48, so 620 bytes, not the 850 those three alone ask)."""
    shape = feature_distance.working_shape(shape, params["joint_width"])
    c = shape[2]
    rows, cols = _tables(shape, params)[0]
    table = 4 * DIMS * rows * cols + 4 * CELLS ** 2 * c * min(BLOCK_ROWS, rows) * cols \
        + 16 * CELLS ** 2 * c * min(FIT_SAMPLES, rows * cols)
    search = MEM_SEARCH * min(width * height, SEARCH_PIXELS)
    return table + search + 12 * c * shape[0] * shape[1] \
        + (MEM_OUT + MEM_OUT_C * c) * width * height


def _cost(shape, width, height, params):
    """Seconds on the reference machine (``texsynth.budget``): per EM iteration and patch size,
    a PatchMatch over the output, its votes and final pass (about 4/3 of the finest level's
    output over all levels), and the finest level's search tables (its lattice points); and the
    copies' alignment after each patch size of every level but the finest (``align_regions``:
    its labelling and seam costs over the level, about a third of the output's pixels a patch
    size). Fitted to 1024 -> 2048 from the 12 MP setts' centre, the 12 MP setts, the brick
    wall and the gravel (quiet: 77-91 s, the alignment 4-11 % of it; predicted 0.95-1.07x).
    The fixed seconds 1.2 -> 2.1 (issue 45: 64^2 -> 256^2 and -> 2048 x 32 read 1.21-1.33 of
    the predictions table's median seconds over cost on two hosts, 32^2 -> 512^2 1.02-1.06).
    The work grows with the channels as (c + ``CHANNEL_BASE``) / (3 + ``CHANNEL_BASE``)."""
    shape = feature_distance.working_shape(shape, params["joint_width"])
    c = shape[2]
    per_channel = (c + CHANNEL_BASE) / (3 + CHANNEL_BASE)
    work = params["iterations"] / 3 * per_channel
    table = sum(r * k for r, k in _tables(shape, params))
    align = COST_ALIGN * params["sizes"] * width * height / 3 * per_channel
    small = min(1.0, width * height / FIT_PIXELS) ** 0.12
    return 2.1 + (COST_OUT * small * params["sizes"] / 2 * width * height
                  + COST_TABLE * table) * work + align


METHOD = register(Method(
    name="texture_optimization",
    label="Texture Optimization",
    description="Optimise the output so every patch is near an exemplar patch (Kwatra et al. "
                "2005), nearest patches by PatchMatch, patch usage kept uniform (Kaspar et al. "
                "2015): keeps long structures such as cracks, mortar lines and weaves",
    function=texture_optimization,
    params=(
        Param("levels", int, 0, "Resolution levels, coarse to fine (capped by the exemplar and "
              "output sizes); 0: enough for the largest patch at the coarsest level to span the "
              "exemplar's texels", 0, 8),
        Param("patch_size", int, 8, "Smallest patch side (pixels); each level also runs the "
              "larger sizes first", 4, 64),
        Param("sizes", int, 2, "Patch sizes per level, each twice the next, large to small", 1,
              4),
        Param("iterations", int, 3, "EM iterations per level and patch size", 1, 20),
        Param("uniformity", float, 2.0, "Weight lambda of the uniform patch usage term (0: off): "
              "higher repeats fewer favourite patches", 0.0, 10.0),
        Param("joint_width", float, 0.0, "Width (pixels) of the joints between the photo's "
              "elements (bricks, setts, blocks); 0: measured from the photo (none where it "
              "has no joint network)", 0.0, 64.0),
        Param("feature_weight", float, FEATURE_WEIGHT, "Weight of the distance to the joints "
              "in the neighbourhood match, against the colours; 0: joints not compared", 0.0,
              8.0),
    ),
    min_exemplar=8,
    memory=_memory,
    cost=_cost,
    positions=True,
))
