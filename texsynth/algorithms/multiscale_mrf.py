"""Multiscale MRF synthesis with Ashikhmin candidates and confidence weighting, periodic.

Neubeck, Zalesny & Van Gool 2004, section 3.1: Paget & Longstaff's non-parametric multiscale
MRF, sampled from the exemplar, with Ashikhmin's candidate search, and confidences.

- The output is a position map ``S``: per pixel, the exemplar pixel whose colour it shows.
- Initialisation: random positions, so the output histogram is the exemplar's.
- A visit to output pixel (i, j): every placed neighbour (i + u, j + v) in the disk
  N = {0 < u^2 + v^2 <= r^2} proposes the exemplar position that continues it,
  S(i + u, j + v) - (u, v) (Ashikhmin, fig. 8), plus ``random_candidates`` random positions; each
  candidate (p, q) is scored by eq. 3,
      dist(i, j, p, q) = sum_(u,v in N) w(i + u, j + v) ||out(i + u, j + v) - in(p + u, q + v)||^2,
  where neighbours outside the exemplar count as the maximal difference; S(i, j) moves to the
  best candidate only when it is better than the current one.
- Confidences (eq. 1-2) and the multigrid (fig. 9) are ``texsynth.blocks.multigrid``'s; on
  level l the neighbourhood offsets are 2^l (u, v) in the exemplar, so every level reads the
  whole exemplar.
- Camera photos (issue 25: 12 MP in, 2048 out): the photo is analysed at its feature scale, its
  full resolution read only where the grid is fine. Each level scores candidates against a
  table of its exemplar positions (``neighbour_table``) at most ``TABLE_ROWS`` long: the
  lattice ``exemplar[::s, ::s]``, s the least power of two that fits (1 up to 1448 x 1448
  pixels), whose neighbours at step 2^l are lattice pixels too when s <= 2^l; the finer levels
  (2^l < s: the finest refinements) read the whole exemplar's neighbourhoods on demand
  (``WindowRows``, 16 bytes a pixel for RGB where a table row is 448), so every exemplar pixel
  can be shown. 12 MP to 2048: 0.8 GiB where the tables would take 13.5.
- Levels (Paget & Longstaff 1998: the coarsest grid's neighbourhood must capture the texture's
  longest interactions): by default (``levels`` 0) enough that the coarsest neighbourhood's
  radius, r 2^(L-1) pixels, spans two texels (``texsynth.blocks.period``), and at least
  ``MIN_LEVELS``: 1024 px photos of a brick wall or layered rock get 8, of gravel 4.
- Each level's values at its scale (issue 25: setts with joints ending inside a stone, stones
  pieced from two halves or run together): level l compares the exemplar's means over boxes of
  2^l pixels (``box_means``; Wei & Levoy 2000, 3 compare a Gaussian pyramid's levels), not
  its pixels. Read pixel by pixel, a step of 2^l samples a joint narrower than 2^l or misses
  it (aliasing), so the coarse levels, whose neighbourhoods alone span a stone and its joints,
  placed stones without seeing the joints, and the fine levels' neighbourhoods (radius r 2^l,
  3 to 12 pixels on levels 0-2) are too small to join them. Share of stone area in stones run
  together (``benchmarks.stones``; the photo 0), seeds 0-2, to 2048: from the 12 MP setts' 1024
  crop 0.98, 0.99, 1.00 before, 0.73, 0.95, 0.89 after; from the 12 MP setts 0.91, 0.53, 0.86
  before, 0.81, 0.69, 0.80 after: better from the crop, level from the 12 MP photo, far from
  the photo both.
- Bricks in rows (issue 25: from the brick wall's 1024 px photo to 2048, the courses stepped
  by about half a course where two copied regions met, several times a 512 crop). Where the
  steps arise (each level's position map rendered at full resolution, its courses' steps read
  by ``texsynth.metrics.course_steps``, seed 0; the photo 0.019): levels 7 to 5, whose box
  means of 32 to 128 px average the 33 px courses away, place copies in random course phase
  (0.12 to 0.13); level 4, the first to see the courses, joins some (0.085); the finer levels
  keep the rest (0.090 at the end): their neighbourhoods (r 2^l <= 24 px) reach across a
  border but each visit moves one pixel, never a whole copy. So after each level between the
  coarsest and the finest whose grid has at most ``ALIGN_PIXELS`` pixels, its copied regions
  slide into phase (``texsynth.blocks.region_shift``: Pritch, Kav-Venaki & Peleg 2009, 3's
  shift-map labels, Kwatra et al. 2003, 3.1's seam cost summed over the level's disk, on the
  level's own grid and box means; copies placed breadth first from the largest, then one
  sweep of single moves): on the brick wall level 3 (step 8, a quarter course) joins them.
  Course steps, seeds 0 and 1: 0.070 and 0.087 before, 0.044 and 0.048 after
  (``benchmarks.brick_rows``; ``benchmarks.straight_cuts``' row disagreement does not see
  them: 0.129 before, 0.126 after); gradient ratio 1.07-1.08 both. Gravel (4 levels, none
  aligned) comes out the same; layered rock: gradient 1.010 -> 1.031, seam 1.00 -> 1.02, its
  cracks laid out anew; the 12 MP setts: gradient 1.013 -> 1.008, the alignment 0.8 s of a
  34 s run under load 6. Aligning level 2 too (step 4, 512 x 512) gained nothing (0.049).

Joints that end inside elements (issue 41: from a 512 px photo of ashlar blocks to 1024, a
"circuit board" of joint lines stopping mid-stone): told the joints' width (``joint_width``,
pixels), the exemplar gets one more channel, each pixel's signed distance to the nearest joint
(``texsynth.blocks.feature_distance``: Lefebvre & Hoppe 2006, 4's feature distance; the joints
of ``texsynth.blocks.joints`` at half that width), scaled to ``feature_weight`` times the
colours' standard deviation. Every level's box means keep it (it varies at the scale of the
element, where a joint a few pixels wide averages away), so eq. 3 matches where a neighbourhood
lies in its element; the output copies the photo's own pixels. Dead-end ratio
(``texsynth.metrics.dead_end_ratio``, joints' half width 2 px), seeds 0-2, 512 -> 1024: the
ashlar blocks (held out of the tuning) 1.47, 1.75, 1.62 without, 1.26, 1.33, 1.37 with; a
512 crop of the aztec flagstones (held out) 3.22, 2.16, 2.67 without, 1.37, 1.89, 2.25 with;
a 512 crop of the concrete pavers 2.58 (seed 0) without, 1.66, 1.65, 1.68 with; the
generated wall (``benchmarks.manmade.bricks``) 1.86, 1.83 (seeds 1, 2) without, 1.05, 1.11,
1.21 with; the CPU time the same (9.5-10.6 s both). The 2048 granite setts' 1024 crop
(held out) to 2048, seed 0, joint width 32 px: 1.48 without, 1.07 with (CPU 28 s, 25 s).
Fewer stubs, not none: the goal (1.25) is met on the generated wall and the setts only.
Weight 4 instead of 2: pavers 1.60, 1.69, 1.48, the generated wall 1.14, 1.14, 1.18 against
1.05, 1.11, 1.21 (those figures: the distance channel alone, width given).

By default (``joint_width`` 0) the width is measured (``texsynth.blocks.joints.joint_scale``:
the scale at which the joint skeleton's two families at right angles are most coherent), and
a second channel, the distance saturated at a joint width, joins the first (see
``texsynth.blocks.feature_distance``); a photo without a joint network (the shared gravel,
rock, asphalt, lawn, dirt and cliff photos) runs the path without the channels, bit for bit.
``feature_weight`` 0 leaves the joints out. Dead-end ratio, 512 -> 1024, seeds 0-2, left out /
by default (measured width in brackets): the pavers' 512 crop (seed 0) 2.58 / 1.43, 1.62,
1.23 (5.7 px); the ashlar blocks 1.47, 1.75, 1.62 / 1.04, 1.07, 1.21 (4 px); the flagstones'
512 crop 3.22, 2.16, 2.67 / 1.96, 1.28, 1.45 (2 px); the brick wall's 512 crop 1.01, 0.99,
1.11 by default (2 px); the generated wall 1.86, 1.83 (seeds 1, 2) / 1.32, 1.46, 1.45 (2 px;
at 2.8 px 1.42, 1.25, 1.25); the setts' 512 crop 2.72, 3.03, 3.47 / 2.49, 2.54, 3.26
(22.6 px; at 32 px 2.58, 2.78, 2.16; the crop holds three courses of the 2048 photo's
setts). The distance alone (one channel) read
1.67, 1.80, 1.53 on the pavers, 1.74, 2.40, 2.10 on the flagstones. CPU from the pavers,
median of 3 in one process under load 12: 6.97 s left out, 9.61 s by default (1.38x: five
working channels for three); the gravel (no joints) adds the measure, 0.41 s. Not yet under
1.25 everywhere: joints still end where two copies meet inside a stone (the flagstones, the
setts), and stones run together where a bed joint of one copy meets the middle of another's
stone.

Where there are joints, the coarsest ``COARSE_LEVELS`` levels (where the joint network is
decided: the finer ones only sharpen it) get ``COARSE_FACTOR`` times the visits T and the
random candidates (Paget & Longstaff 1998: the coarse grid fixes the long interactions), those
of at most ``COARSE_PIXELS`` (a 512 photo to 1024: its coarsest three, 64 x 64 and less, so the
cost is small; a 32 px exemplar to 512 has 128 x 128 at its coarsest, where 4x had cost 5.7x).
Dead-end ratio, 512 -> 1024, seeds 0-2, before / after: pavers 1.43, 1.62, 1.23 / 1.30, 1.20,
1.29; flagstones 1.96, 1.28, 1.45 / 1.46, 1.28, 1.54; setts 2.49, 2.54, 3.26 / 2.37, 2.61,
2.06; ashlar 1.04-1.21 / 1.10, 1.04, 1.01; but the generated wall 1.32, 1.46, 1.45 / 1.44,
1.50, 1.49. CPU 1.0-1.1x (flagstones 14.7 -> 15.0-16.4 s under load 7); twice, on two levels:
pavers 1.32, 1.47, 1.14, ashlar 1.30 on seed 0. The gravel (no joints) runs as before, bit for
bit.

Where there are joints, after each of the levels ``REPAIR_LEVELS`` (2-4: steps 4-16 px, whose
grids still draw random candidates) the joints its map renders (``texsynth.blocks.joint_repair``:
each grid point's exemplar block at full resolution, read by the rule fitted at the measured
width) that stop within 1.5 joint widths of a seam between copies are the synthesis' own; the
grid points within ``REPAIR_REACH`` neighbourhood radii of them are relaxed again from
confidence 0 (filled from the confident rim inward), ``REPAIR_ROUNDS`` times. Dead-end ratio,
each photo to twice its size, seeds 0-2, before / after: pavers' 512 crop 1.30, 1.20, 1.29 /
1.15, 1.17, 1.28 (the paver stubs ending mid-stone gone at full resolution); generated wall
1.44, 1.50, 1.49 / 1.42, 1.33, 1.32; levels 1-4 and two rounds: pavers 1.17, 1.35, 1.14, wall
1.25, 1.28, 1.18, but 1.3-1.6x the CPU. Gradient ratio and repeat peak unchanged (1.09-1.10,
0.18-0.19 on the pavers; 1.01-1.02, 0.46-0.47 on the wall). Flagstones (aztekWall's 512 centre)
1.46, 1.28, 1.54 / 1.12, 1.05, 1.38; brick wall 0.90, 1.08, 1.09 / 0.98, 0.95, 1.05 and ashlar
1.10, 1.04, 1.01 / 1.10, 1.08, 1.03. CPU 1.00-1.16x (median 1.10, A/B in one process). Dead
ends tested within a block (the level's step) more of a seam: worse (pavers 1.38, 1.24, 1.18,
flagstones 1.54, 1.44).

Where the generated wall's stubs come from, and what was tried and left out (issue 41; dead-end
ratio, each photo to twice its size, seeds 0-2; as it is: pavers' 512 crop 1.15, 1.17, 1.28,
the wall 1.42, 1.33, 1.32, flagstones 1.12, 1.05, 1.38). Of the wall's 344 dead ends (seed 0)
77 lie within 1.5 joint widths of a seam: the rest are the photo's own, copied from its centre
(its rows and columns within 20 px of the edges used 0.07-0.12 times a pixel, the centre 14),
where its joints end more often (6.8 per 1000 px of joint beyond 64 px of the edges, 5.8 over
the photo); the photo's own density weighted by that usage reads 1.38 alone. The coarsest
neighbourhood (radius 192 px, 7 levels) fits whole only in the wall's central 64 x 96 px.
Neighbours outside the exemplar read mirrored (as the measure reads the photo) instead of
costing D: the wall 1.04, 1.19, 1.23, brick wall 1.02, 0.96, 1.05, ashlar 1.11, 1.09, 1.17,
setts 1.05, 1.03, 1.06, but pavers 1.29, 1.36, 1.34 and flagstones 2.37, 1.70, 1.69 (joints
ending mid-stone: the rim's mirror shows elements the photo has nowhere); mirrored plus D / 4
or D / 16: pavers 1.66, 1.16, 1.49 / 1.26, 1.49, 1.44; mirrored on the three coarsest levels
only: pavers 1.25, 1.52, 1.67; on the coarsest alone: pavers 1.34, 1.35, 1.32, the wall 1.30,
1.29, 1.44; on the finer ones only: the wall 1.37, 1.30, 1.14, flagstones 1.36, 0.84, 1.58. The
joint repair on level 1 too (and 0), a hole's new positions kept only where its dead ends
became fewer: pavers 1.16, 1.16, 1.30 (1.16, 1.16, 1.28), the wall 1.38, 1.35, 1.29 (1.37,
1.33, 1.28); that test on levels 2-4: pavers 1.23, 1.28, 1.32. No random candidates on levels
0-1 (0-2): pavers 1.20, 1.26, 1.21 (1.21, 1.23, 1.19), the wall 1.39, 1.34, 1.29 (1.43, 1.36,
1.25). Six levels: pavers 1.22, 1.70, 1.51, the wall 1.38, 1.36, 1.43. The flagstones' photo
has 6 dead ends (the pavers' 20): an output twice its size about 24 (80), a seed's ratio within
about 20 % (11 %) of its rate.
Neighbourhoods running off the exemplar scored on their inside part only, normalised by its
weight (Wei & Levoy 2000, 3.2's partial neighbourhoods; Efros & Leung 1999's masked SSD: a
table row's outside neighbours X = 0, Q = 0, a per-row inside mask M, distance
(Y_p . Z + M_p . w|O|^2) / M_p . w, infinite below a least inside share), where there are
joints: the wall is mended, the pavers and flagstones lose as with the mirror (the photo's rim
cuts their elements, and a copy of it seams them mid-stone). Share 0.5 on every level: pavers
1.38, 1.35, 1.55, the wall 1.03, 1.18, 0.91, flagstones 2.02, 2.20, 1.67; on the coarsest three:
1.56, 1.49, 1.53 / 0.83, 0.88, 0.84 (bricks run together) / 1.68, 2.07, 1.10; share 0.9, every
level: 1.25, 1.24, 1.48 / 1.18, 1.27, 1.33 / 1.53, 1.10, 1.46; share 0.75, every level: 1.31,
1.29, 1.06 / 1.01, 1.01, 1.02 / 1.42, 1.24, 1.46, brick wall 1.14, 0.99, 0.95, ashlar 1.06,
1.06, 1.27, setts 1.03, 1.02, 0.89 (CPU 1.16x on the flagstones); share 0.75 on the coarsest
two (one): pavers 1.11, 1.37, 1.05 (1.27, 1.41, 1.60), flagstones 0.88, 1.52, 1.47 (1.25, 1.18,
1.25).

Where there are joints, the photo's own dead ends cost a candidate that would copy them
(issue 41; ours: a cost on the exemplar position, as ``texture_optimization``'s usage term):
each table level's candidate p whose block [p, p + 2^l) grown by ``DEAD_END_MARGIN`` sigma holds
one of the photo's dead ends (``texsynth.blocks.joints``' skeleton of the photo, as
``texsynth.metrics.dead_end_ratio`` reads it) pays ``DEAD_END_COST`` D per unit of neighbour
weight (its row's Q + c_e D, so eq. 3 gains c_e D sum(w): a 0.3 % share of neighbours outside).
Why: of the wall's 344 dead ends (seed 0) 74 lie at seams, 270 inside copies, and the photo's
dead-end pixels were copied 5.6 times each where a photo pixel is copied 4.0 times on average
(the centre, where the stubs lie, is copied most): that 1.4x is the ratio. With the cost: 284
copies of them (4.5 each), 79 dead ends at seams, 218 inside, 297 in all (skeleton 41921 ->
42285 px). Dead-end ratio, each photo to twice its size, seeds 0-2, before / after (the cases
of ``benchmarks.sections.elements``' methods): pavers' 512 crop 1.15,
1.17, 1.28 / 0.94, 0.85, 0.90; generated wall 1.42, 1.33, 1.32 / 1.22, 1.08, 0.96; flagstones
1.12, 1.05, 1.38 / 1.09, 0.75, 1.14; brick wall 0.98, 0.95, 1.05 / 0.79, 0.92, 0.76; ashlar
1.10, 1.08, 1.03 / 1.03, 0.90, 0.89; setts 1.05, 0.96, 1.04 / 0.62, 0.64, 0.61 (below 1: the
output copies fewer of the photo's stubs than the photo shows). Gradient ratio 1.09-1.10 ->
1.07-1.09 (pavers), 1.02 -> 1.02-1.04 (wall), 1.01-1.02 -> 0.98-1.00 (flagstones), 0.99-1.00
-> 0.97-0.98 (brick); repeat peak within 0.04 of before, under the photo's + 0.1 (flagstones
0.24, photo 0.21); the gravel (no joints) bit for bit; CPU 1.0-1.1x. Held out, seeds 3-5:
pavers 1.22, 1.33, 1.22 / 1.04, 1.00, 0.85, the wall 1.48, 1.32, 1.33 / 1.05, 1.13, 1.13,
flagstones 1.48, 1.16, 1.53 / 1.36, 1.16, 1.07 (6 dead ends in its photo: a seed's ratio is
within about 20 % of its rate, and the cost's best there is narrow). These figures were read on
the skeleton before its wrap fix (``Joints.skeleton(wrap=True)``); on it, the benchmark reads
seeds 0-2: pavers 0.89, 0.87, 0.83, the wall 1.16, 1.06, 0.97, flagstones 1.35, 1.18, 1.37
(``python -m benchmarks --only elements``), and the wall's courses still step where its copies
meet across the wrap. Cost 0.002: flagstones
1.72, 1.24, 1.10, pavers 1.23, 0.69, 1.04, the wall 1.09, 1.22, 1.04; 0.005: pavers 0.79,
0.74, 0.75, wall 0.93-0.95, setts 0.49-0.51, but flagstones 1.38, 1.24, 1.43; 0.02: wall
0.66-0.77 with its courses stepped where copies dodge the stubs (skeleton 45102 px), and on
levels 0-1 only, wall 1.31, 1.29, 1.29. Tried before it and left out: the alignment
(``align_regions``) on levels 1 and 0 too, moves of one step: the wall 1.41, 1.32, 1.35 (CPU
1.4x); on level 1 alone, moves of two steps (one): 1.37, 1.32, 1.36 (1.40, 1.31, 1.31).

Two rounds of the joint repair (``REPAIR_ROUNDS``; issue 41, the flagstones over the goal on
the wrap-fixed skeleton). Dead-end ratio, each photo to twice its size, seeds 0-5, one round /
two: flagstones 1.35, 1.18, 1.37, 1.48, 1.60, 1.19 / 0.93, 0.71, 1.06, 1.12, 1.29, 1.06, held
out seeds 6-11 1.31, 1.25, 1.26, 1.89, 1.01, 1.22 / 0.96, 0.78, 0.79, 1.38, 0.90, 1.28 (mean
1.34 / 1.02 over the 12 seeds; the photo's 6 dead ends leave a seed about 20 % of noise);
pavers 0.89, 0.87, 0.83, 0.92, 1.07, 0.96 / 0.78, 0.67, 0.90, 1.00, 0.96, 0.90; the generated
wall (locked, below) 1.05, 0.99, 0.96, 0.87, 1.04, 1.03 / 1.02, 0.87, 0.91, 0.81, 1.02, 1.09;
two rounds: ashlar 0.88, 0.70, 0.86, 0.71, 0.86, 0.87, brick wall 0.82, 0.72, 0.71, 0.78,
0.78, 0.84, setts 0.60, 0.74, 0.57, 0.77, 0.69, 0.73. Gradient ratio: flagstones 0.96-1.01 /
0.95-0.99, the rest within 0.01; repeat peak within 0.02 (flagstones 0.23, photo 0.21). CPU:
the wall's repair 3 of 14.6 s under the profiler, the second round (a full-resolution render
and skeleton more per level, its holes fewer) about 1.1x the run. Tried and left out: three
rounds, flagstones 1.09, 0.99, 1.72, 1.09, 1.35, 1.52; level 1 repaired too (one round) 1.10,
1.73, 1.24, 1.19, 1.70, 1.19; ``DEAD_END_MARGIN`` 3 (one round) 1.32, 1.36, 1.57, 1.17, 1.10,
0.71; no second round where its holes cover over half the grid (the wall's level 4: 97 %, its
second round 0.32 s): flagstones 1.04, 1.05, 1.45, 1.23, 1.09, 1.10 and 1.34, 1.28, 0.93, 1.51,
0.85, 1.16 on seeds 6-11 (mean 1.17: the coarse level drawn anew is what mends them). CPU A/B
against 2a84d3b (separate processes, seed 0, medians of 6 under load 2-3): the wall 4.62 ->
5.78 s (1.25x; one round 1.10x), the pavers 6.06 -> 6.96 s (1.15x; one round 1.07x).

Courses across the wrap (issue 41: the generated wall's output, 960 x 896, is 37 1/3 courses
high, so going once around the torus its copies' course phase must break; aligned copy by copy,
``align_regions``' moves of a few steps, the break was a patch about 140 rows high of
half-height bricks and head joints that stop, its ratio 1.16 on seed 0 though the eye saw it
first). Where the photo's courses have a lattice that it repeats along
(``texsynth.blocks.rhythm.lattice``: its course period P and bond (Q, s), the photo correlating
with itself shifted by (P, s) and by (0, Q) at least ``LOCK_REPEAT``), each level from
``LOCK_FINEST`` whose step is at most P / ``LOCK_STEPS`` (the wall: levels 1-3) moves its
copies, after their
alignment, into one phase of the lattice, broken once along a straight row where the seam
between the two phases costs least (``texsynth.blocks.region_shift.lock_lattice``): the break
is a sliver course, no step, and 99.2 % of the wall's pixels (seed 0) share one phase (99.4 %
with level 0 locked too, 0.8 s more; a copy carried across the wrap moved as one piece, 93 %,
the break grown by the finer levels into a blob 120 rows high). Dead-end ratio, the generated
wall to twice its size, seeds 0-5, before / after: 1.16, 1.06, 0.97, 0.97, 1.17, 1.17 / 1.05,
0.99, 0.96, 0.87, 1.04, 1.03; gradient ratio 1.02-1.04 / 1.02-1.03; repeat peak 0.47 / 0.57
(photo 0.55); CPU 5.4 / 5.1 s. No other photo of the benchmark has such a lattice (the brick
wall's bond is not found; the pavers' 512 crop correlates 0.25 and 0.24 along its lattice's
vectors, the wall 0.46 and 0.42): locked, the pavers read 0.48, 0.48, 0.53, 0.80, 0.49, 0.52
(from 0.89, 0.87, 0.83, 0.92, 1.07, 0.96), whole pavers in a perfect lattice, but their repeat
peak 0.74 (photo 0.24), so they are left as they were, bit for bit. The phase's break placed
within a quarter of the seam costs' range of the least (not ``BREAK_SLACK``): a course whose
upper half is the next course's (head joints off), the wall's seed 0 1.13.

Periodic output: output neighbourhoods wrap around the canvas, so the result tiles. Colour:
channels are compared jointly and positions copy whole pixels.

Deviations, one line each (and those of ``texsynth.blocks.multigrid``):
- a neighbour outside the exemplar costs w (D + |O - mean|^2) instead of w D (D = the maximal
  difference), which lets eq. 3 be one dot product; such candidates lose either way;
- "placed" neighbours are those visited at least once on this level (w > 0); the random
  positions of the initialisation propose no continuation, the ``random_candidates`` do that job;
- production sizes (k-coherence refinement, after Tong et al. 2002 and Ashikhmin 2001): a level
  whose grid has more than ``REFINE_PIXELS`` pixels only refines the coarser level's positions:
  its candidates are the continuations of the 8 nearest neighbours alone (no random ones), and
  it is visited ``REFINE_VISITS`` times instead of T; the distance still uses the whole disk;
- a pixel whose candidates are all its current position is not scored (it would stay);
- a level with a lattice (s > 1) places its random starts and random candidates on the lattice
  only, positions quantised to s <= 2^l, finer than its grid's spacing (2^l pixels);
- with ``exemplar_tiles`` a lattice wraps with the period of ``exemplar[::s, ::s]``, which
  differs from the exemplar's by less than s pixels when s does not divide its size.
- levels reading whole-exemplar windows (2^l < s: the finest of a photo over ``TABLE_ROWS``
  pixels) compare pixels, not box means; a lattice's box starts at its point (s > 1), not
  centred on it;
- where there are joints the feature distance and its saturation are two more exemplar
  channels, compared and centred as colours are (Lefebvre & Hoppe: the distance, after a PCA);
- where there are joints the coarsest levels get more visits and random candidates than T;
- (ours) where there are joints, levels ``REPAIR_LEVELS`` relax again around the joints that
  stop at a seam (``joint_repair``);
- (ours) where the courses have a lattice the photo repeats along, the levels from
  ``LOCK_FINEST`` of step at most P / ``LOCK_STEPS`` lock their copies into one phase of it,
  broken once (``region_shift.lock_lattice``);
- (ours) where there are joints, a candidate copying one of the photo's dead ends costs
  ``DEAD_END_COST`` D more per unit of weight (table levels only, not the windows');
- (ours, not in Neubeck et al. or Paget & Longstaff) after each level but the coarsest (its
  copies are the random start's) and the finest, on a grid of at most ``ALIGN_PIXELS`` pixels
  that reads tables (not windows), whole copies move by up to ``SHIFT`` grid steps each way
  where that lowers their seam cost (``align_regions``: placed breadth first from the
  largest, then ``SWEEPS`` sweeps of single moves).

References
----------
Neubeck et al. 2004, section 3.1 (eq. 1-3, fig. 9); Paget & Longstaff 1998;
Ashikhmin 2001 (fig. 8); Tong et al. 2002; Wei & Levoy 2000, section 3; Pritch,
Kav-Venaki & Peleg 2009, section 3; Kwatra et al. 2003, section 3.1.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import maximum_filter, uniform_filter1d

from ..blocks import feature_distance, joint_repair, multigrid, region_shift
from ..blocks.joints import luma
from ..blocks.multigrid import grid_shapes, level_count
from ..blocks.period import texel_size
from ..blocks.rhythm import lattice
from ..blocks.search import Rows, Scratch, WindowRows, best_candidate, disk_offsets, neighbour_table
from ..registry import Method, Param, register

__all__ = ["multiscale_mrf", "METHOD", "REFINE_PIXELS", "REFINE_VISITS", "TABLE_ROWS",
           "box_means", "lattice_stride"]

#: A level with a grid larger than this (pixels) refines with coherent candidates only.
REFINE_PIXELS = 512 * 512
#: Visits per pixel on such a level.
REFINE_VISITS = 2
#: Reference seconds of one round of ``multigrid.relax`` beyond its pixels' work (its lattice
#: draw, the whole-grid need and confidence arrays, a visit's calls), per value compared by a
#: candidate's visit, and per pixel of an aligned level's grid (``align_regions``: ``SETTLE_COST``
#: + ``SETTLE_SIDE_COST`` / E, E the exemplar's side at the level's step, as small copies have
#: more border): least squares on each level's CPU time (23 aligned and 45 relaxed levels of
#: brick, pool_water and noise exemplars, 32-256 px to 128-1024 px, 2048 x 32, 1024 x 256),
#: at speed 0.35 (issue 40: the former 0.0247 per spacing^2 T told the coarsest level 16 % of
#: the progress for 8 % of the time at 128 -> 256). The predictions benchmark's three rows,
#: cost x speed over CPU seconds in one process under load 4: 0.72, 1.01, 1.04 (before: 1.31,
#: 0.77, 0.84).
ROUND_COST, VISIT_COST = 1.37e-3, 1.62e-9
#: A random candidate's cost in neighbours' continuations (those repeat where a copy carries on,
#: and are scored once): the same fit, 3.7.
RANDOM_WEIGHT = 3.7
SETTLE_COST, SETTLE_SIDE_COST = 3.7e-5, 1.46e-3
#: The grid's aspect ratio over which its alignment takes twice as long: the walk's waves cross
#: its long side, each counting every region (9 waves on a 128^2 grid, 25 on 128 x 512, 128 on
#: 16 x 1024: there 55 % of the run where the square grids' model told 19 %).
SETTLE_ASPECT = 16
#: Neighbours whose continuations a refining level proposes (the 3 x 3 ring: nearest first).
REFINE_PROPOSERS = 8
#: The fewest levels the automatic choice gives (the former default).
MIN_LEVELS = 4
#: Texels the coarsest neighbourhood's radius spans: a texel and its joints with the next on
#: every side (one texel across left the setts' joints in fragments: gradient ratio 0.87).
REACH_TEXELS = 2
#: The most exemplar positions a level's table holds (448 bytes each for RGB, radius 3; with
#: C channels, 4 / (C + 1) of it).
TABLE_ROWS = 1 << 21
#: The largest move of a copied region, in grid steps each way, when a level's copies are
#: slid into phase (``align_regions``).
SHIFT = 2
#: The largest grid (pixels) whose copies are slid into phase.
ALIGN_PIXELS = 256 * 256
#: Where there are joints, the cost of a candidate whose block (grown by ``DEAD_END_MARGIN``
#: joint half widths) holds one of the photo's own dead ends, per unit of neighbour weight, in
#: units of D (the maximal difference: an outside neighbour's cost).
DEAD_END_COST, DEAD_END_MARGIN = 0.003, 2.0
#: Where the courses have a lattice (``texsynth.blocks.rhythm.bond``), the levels from the second
#: finest up whose course period spans at least this many grid steps lock their copies into its
#: phase (``region_shift.lock_lattice``; on the finest too: the wall's picture alike, 0.8 s more).
LOCK_STEPS, LOCK_FINEST = 2, 1
#: The least correlation of the photo with itself shifted by a period vector of its lattice for
#: the lock (the generated wall 0.46, 0.42; the pavers' 512 crop 0.25, 0.24, whose output
#: locked repeated itself: repeat peak 0.74, photo 0.24).
LOCK_REPEAT = 0.35
#: Rounds of single region moves per level after the walk.
SWEEPS = 1
#: The feature-distance channel's standard deviation, in the colours' (``feature_distance``).
FEATURE_WEIGHT = 2.0
#: The coarsest levels, where the joint network is decided (issue 41), get this many times the
#: visits and random candidates (their grids are small: a few hundred pixels).
COARSE_LEVELS, COARSE_FACTOR, COARSE_PIXELS = 3, 4, 64 * 64
#: Where there are joints, the finest levels whose dead ends at seams are synthesized again
#: (``joint_repair``), the rounds of it, and the reach of a hole (the level's neighbourhood
#: radii, r 2^l pixels).
REPAIR_LEVELS, REPAIR_ROUNDS, REPAIR_REACH = range(2, 5), 2, 1.5
#: A repaired level's seconds: per output pixel (its map rendered and read at full resolution)
#: and a share of the level's visits (the holes relaxed again).
REPAIR_PIXEL_COST, REPAIR_SHARE = 5e-7, 0.5  # fitted on bricks 128 -> 256, pavers 512 -> 1024
#: Reference seconds of a table level's table per value of a row (``neighbour_table``, K (C + 1)
#: a lattice pixel): 1024^2 tables of radius 3 (CPU 0.12, 0.22, 0.25 s for C = 1, 3, 5 at speed
#: 0.29; gathered a band at a time: 1.7e-8 per neighbour and channel had read the former fill's
#: 0.12, 0.41, 0.75 s).
TABLE_COST = 5.7e-9
#: Where there are joints, the seconds per exemplar pixel of reading them before the levels
#: (the width measured, the rule fitted, the distance channels, the photo's own dead ends):
#: 2.4e-6 and 1.8e-6 measured on a 1024 crop and the whole rectified 12 MP setts (8.2 MP),
#: where the model had told 0.76x and 0.58x the run's time without it.
JOINT_PIXEL_COST = 2e-6


class _Level:
    """Eq. 3 as one dot product per candidate. Each exemplar pixel p has a row
    ``Y_p = [X, Q]``: X its neighbours' values at this level's step, Q = |X|^2, or for a
    neighbour outside the exemplar X = 0 and Q = D, the maximal difference. A visited output
    pixel has a row ``Z = [-2 w O, w]`` (O its neighbours' colours, w their confidences), so
    ``Y_p . Z + sum w |O|^2`` is eq. 3; the last sum is the same for every candidate and is
    left out. Colours are centred on the exemplar mean.

    ``rows`` are a table (``Rows`` of ``neighbour_table``) of the exemplar lattice
    ``exemplar[::stride, ::stride]`` at step 2^l / stride, whose positions this level works in
    (mapped from and to the flat positions of the whole exemplar, ``width`` wide), or, with
    ``stride`` 0, ``WindowRows`` of the whole exemplar (its interleaved layout)."""

    #: Output pixels visited at once (keeps the gathered rows in cache).
    CHUNK = 1024

    def __init__(self, rows, colours, shape, stride, width, offsets, step, wrap,
                 random_candidates, proposers=None):
        k = len(offsets)
        self.rows, self.colours = rows, colours
        self.shape, self.n, self.k, self.wrap = shape, shape[0] * shape[1], k, wrap
        self.stride, self.width, self.windows = max(1, stride), width, stride == 0
        self.c, self.step = colours.width, step
        self.du = (step * offsets[:, 0]).astype(np.int32)
        self.dv = (step * offsets[:, 1]).astype(np.int32)
        self.offsets = offsets
        self.random_candidates = random_candidates
        self.proposers = k if proposers is None else min(proposers, k)
        self.duv = self.du * np.int32(shape[1]) + self.dv  # a continuation's flat offset
        self.scratch = Scratch()
        self._around = (None, None, None)  # _neighbours' tables, for the last grid shape

    def _to_level(self, p):
        if self.stride == 1:
            return p
        pr, pc = np.divmod(p, self.width)
        return (pr // self.stride) * self.shape[1] + pc // self.stride

    def _to_exemplar(self, q):
        if self.stride == 1:
            return q
        qr, qc = np.divmod(q, self.shape[1])
        return ((qr * self.width + qc) * self.stride).astype(np.int32)

    def visit(self, source, confidence, rows, cols, rng, tick):
        """One visit of the pixels (rows, cols), none in another's neighbourhood: each moves to
        its best candidate when that beats its current position. Returns the new positions.
        Taken ``CHUNK`` pixels at a time, so every temporary stays small and in cache;
        ``tick()`` after each chunk."""
        out = self._to_level(source[rows, cols])
        for s in range(0, len(rows), self.CHUNK):
            sl = slice(s, s + self.CHUNK)
            out[sl] = self._visit(source, confidence, rows[sl], cols[sl], out[sl], rng)
            tick()
        return self._to_exemplar(out)

    def _visit(self, source, confidence, rows, cols, current, rng):
        p = self.proposers
        if self.random_candidates:  # every pixel is offered new positions
            nb, nw = self._neighbours(source, confidence, rows, cols, self.k)
            extra = rng.integers(self.n, size=(len(rows), self.random_candidates))
            cand = np.concatenate([self._continuations(nb[:, :p], nw[:, :p]),
                                   extra.astype(nb.dtype)], axis=1)
            return self._best(nb, nw, current, cand)
        # A pixel offered nothing but its current position keeps it unscored.
        cand = self._continuations(*self._neighbours(source, confidence, rows, cols, p))
        todo = np.flatnonzero(((cand != current[:, None]) & (cand != self.n)).any(axis=1))
        out = current.copy()
        if len(todo):
            nb, nw = self._neighbours(source, confidence, rows[todo], cols[todo], self.k)
            out[todo] = self._best(nb, nw, current[todo], cand[todo])
        return out

    def _neighbours(self, source, confidence, rows, cols, k):
        """The first k neighbours' positions (this level's) and confidences w, (B, k) each;
        their flat indices on the torus a row's part plus a column's (tables of every grid row's
        and column's wrapped offsets, made once per grid: a modulo of every pair cost 8 %)."""
        shape, down, across = self._around
        if shape != source.shape:
            gh, gw = shape = source.shape
            down = ((np.arange(gh)[:, None] + self.offsets[:, 0]) % gh * gw).astype(np.int32)
            across = ((np.arange(gw)[:, None] + self.offsets[:, 1]) % gw).astype(np.int32)
            self._around = shape, down, across
        flat = down[rows] + across[cols]
        if k < self.k:
            flat = flat[:, :k]
        return self._to_level(source.ravel()[flat]), confidence.ravel()[flat]

    def _continuations(self, nb, nw):
        """Ashikhmin: each placed neighbour (w > 0) proposes the position that continues it;
        the others propose nothing (``n``)."""
        h, w = self.shape
        k = nb.shape[1]
        pr, pc = np.divmod(nb, w)
        pr -= self.du[:k]
        pc -= self.dv[:k]
        if self.wrap:
            cand = (pr % h) * w + pc % w
            cand[nw <= 0] = self.n
            return cand
        # 0 <= pr < h as one unsigned comparison; pr w + pc = nb - (du w + dv)
        ok = (_unsigned(pr) < h) & (_unsigned(pc) < w) & (nw > 0)
        return np.where(ok, nb - self.duv[:k], self.n)

    def _best(self, nb, nw, current, cand):
        k, c = self.k, self.c
        b = len(nb)
        z = np.empty((b, k, c + 1) if self.windows else (b, k * (c + 1)), np.float32)
        o = self.colours.take(nb.ravel(), self.scratch.get("colours", b * k, c)).reshape(b, k, c)
        if self.windows:
            z[:, :, :c] = np.multiply(o, (-2.0 * nw)[:, :, None])
            z[:, :, c] = nw
            z = z.reshape(b, k * (c + 1))
        else:
            # each weight repeated over its C values: a broadcast over C = 3-5 cost 2.5x
            np.multiply(o.reshape(b, k * c), np.repeat(-2.0 * nw, c, axis=1), out=z[:, :k * c])
            z[:, k * c:] = nw
        return best_candidate(self.rows, cand, z, current, self.n, self.scratch)


def _unsigned(a):
    """``a`` (int32 or int64) read as unsigned: a negative value is then larger than any bound."""
    return a.view(np.uint32 if a.dtype == np.int32 else np.uint64)


def multiscale_mrf(exemplar, width, height, rng, progress, radius=3, visits=4,
                   random_candidates=2, levels=0, exemplar_tiles=False, joint_width=0.0,
                   feature_weight=FEATURE_WEIGHT):
    """Relax a position map on a multigrid, each pixel moving to the best of its neighbours'
    continuations and random candidates, with confidences (see the module notes).

    Parameters
    ----------
    exemplar : float32 array (H, W, C)
        The sample, validated by ``texsynth.synthesize``.
    width, height : int
        The output size, larger or smaller than the exemplar.
    rng, progress : numpy.random.Generator, texsynth.progress.Progress
        The seeded generator and the progress reporter ``texsynth.synthesize`` makes.
    radius : int
        Radius r of the disk neighbourhood compared (pixels at each level).
    visits : int
        Visits T per pixel and level; confidence grows by 1/T a visit.
    random_candidates : int
        Random exemplar positions tried per visit besides the neighbours' continuations.
    levels : int
        Multigrid levels (capped by the exemplar and output sizes); 0: enough for the coarsest
        neighbourhood to span the exemplar's texels.
    exemplar_tiles : bool
        The exemplar itself tiles: neighbourhoods may wrap around its edges.
    joint_width : float
        The joints' width in pixels on a man-made surface (bricks, blocks, setts): the
        neighbourhoods also compare the signed distance to the nearest joint (Lefebvre & Hoppe
        2006, 4); 0 (the default) measures it (``texsynth.blocks.joints.joint_scale``), and a
        photo without a joint network (gravel, rock) is synthesized without the channel.
    feature_weight : float
        That channel's weight, in units of the colours' standard deviation; 0 leaves it out.

    Returns
    -------
    image : numpy.ndarray
        float32 (height, width, C), periodic.
    positions : numpy.ndarray
        int32 (height, width, 2), the position map ``S``: ``image`` is the exemplar read at it.

    References
    ----------
    Neubeck, Zalesny & Van Gool 2004, section 3.1, eq. 1-3 (confidences and the distance);
    Paget & Longstaff 1998 (the multiscale MRF); Ashikhmin 2001, fig. 8 (the candidates);
    Tong et al. 2002 (k-coherence refinement); Wei & Levoy 2000, 3 (levels compared at their
    scale); Pritch, Kav-Venaki & Peleg 2009, 3 and Kwatra et al. 2003, 3.1 (copies aligned);
    Lefebvre & Hoppe 2006, 4 (the feature-distance channel).

    Examples
    --------
    >>> import numpy as np, texsynth
    >>> photo = np.random.default_rng(0).random((16, 16, 3), dtype=np.float32)
    >>> image, positions = texsynth.synthesize_positions(photo, 24, 20, method="multiscale_mrf",
    ...                                                  seed=1)
    >>> image.shape, np.array_equal(photo[positions[..., 0], positions[..., 1]], image)
    ((20, 24, 3), True)
    """
    joints = feature_distance.fit(exemplar, joint_width, feature_weight)
    work = exemplar if joints is None else feature_distance.augment(exemplar, joint_width,
                                                                    feature_weight, joints)
    out, positions = _synthesize(work, width, height, rng, progress, radius, visits,
                                 random_candidates, levels, exemplar_tiles,
                                 1 if work is exemplar else COARSE_FACTOR,
                                 None if work is exemplar else (luma(exemplar), joints),
                                 None if joints is None else lattice(exemplar, LOCK_REPEAT))
    if work is exemplar:
        return out, positions
    return exemplar[positions[:, :, 0], positions[:, :, 1]], positions


def _synthesize(exemplar, width, height, rng, progress, radius, visits, random_candidates,
                levels, exemplar_tiles, factor=1, repair=None, lattice=None):
    h, w, c = exemplar.shape
    if min(h, w) < 2 * radius + 1:
        raise ValueError(f"the exemplar ({w} x {h}) is smaller than the neighbourhood "
                         f"(radius {radius}: {2 * radius + 1} x {2 * radius + 1}); use a smaller "
                         "radius or a larger exemplar")
    offsets = disk_offsets(radius)
    if levels == 0:
        levels = auto_levels(exemplar, radius)
    shapes = grid_shapes(width, height, level_count(exemplar.shape, width, height, radius, levels))
    colours = exemplar.reshape(h * w, c)
    mean, dmax = _channel_statistics(exemplar)
    progress(0.0, "centring the exemplar")  # Esc between whole-photo passes of a 12 MP photo
    centred = exemplar - mean
    stride = lattice_stride(exemplar.shape)

    def refines(lv):
        return shapes[lv][0] * shapes[lv][1] > REFINE_PIXELS

    def boost(lv):  # the coarse grids that decide the joint network (COARSE_LEVELS)
        small = shapes[lv][0] * shapes[lv][1] <= COARSE_PIXELS
        return factor if lv >= len(shapes) - COARSE_LEVELS and small else 1

    ends = None if repair is None else joint_repair.photo_ends(*repair)
    kept = {}  # the table array, refilled by every table level; the windows, built once

    def make_level(lv, tick):
        step = 2 ** lv
        candidates = (0 if refines(lv) else boost(lv) * random_candidates,
                      REFINE_PROPOSERS if refines(lv) else None)
        if stride <= step:  # a table of the lattice
            sub = box_means(centred, step, stride, exemplar_tiles, kept)
            cost = None  # Q + c_e D: eq. 3 gains c_e D sum(w) at a stub
            if ends is not None:
                cost = DEAD_END_COST * dmax * _near_ends(ends, step, repair[1].sigma)[::stride,
                                                                                      ::stride]
            table = neighbour_table(sub, offsets, step // stride, exemplar_tiles, dmax,
                                    kept.get("table"), tick, cost)
            kept["table"] = table
            level = _Level(Rows(table), Rows(sub.reshape(-1, c)), sub.shape[:2], stride, w,
                           offsets, step // stride, exemplar_tiles, *candidates)
        else:  # the whole exemplar, rows on demand
            if "windows" not in kept:
                kept.pop("table", None)
                kept["windows"] = WindowRows(centred, radius * step, exemplar_tiles, dmax)
                tick()
            level = _Level(kept["windows"].at(offsets, step), Rows(centred.reshape(h * w, c)),
                           (h, w), 0, w, offsets, step, exemplar_tiles, *candidates)
        return level

    def pool(lv):
        if stride <= 2 ** lv and stride > 1:
            sh, sw = -(-h // stride), -(-w // stride)
            qr, qc = np.divmod(np.arange(sh * sw), sw)
            return ((qr * w + qc) * stride).astype(np.int32)
        return None

    aligned = _aligned(width, height, len(shapes), [])

    def visits_of(lv):
        return min(visits, REFINE_VISITS) if refines(lv) else visits * boost(lv)

    costs = _level_costs(exemplar.shape, width, height,
                         {"radius": radius, "levels": levels, "visits": visits,
                          "random_candidates": random_candidates}, factor, repair is not None)

    def settle(lv, level, source, tick):
        _, aligning, repairing = costs[lv]
        split = aligning / max(aligning + repairing, 1e-12)  # the settling's share: aligning
        if lv in aligned and not level.windows:
            source = _align(level, source, radius, lambda f: tick(split * f))
        if (lattice is not None and LOCK_STEPS * 2 ** lv <= lattice[0] and lv >= LOCK_FINEST
                and level.stride == 1 and not level.windows):
            source = _lock(level, source, repair[0], lattice)
        if repair is not None and lv in REPAIR_LEVELS:
            source = _repair(level, source, lv, visits_of(lv), (height, width), repair,
                             REPAIR_REACH * radius * 2 ** lv, exemplar_tiles, rng,
                             lambda f: tick(split + (1 - split) * f))
        return source

    source = multigrid.synthesize_positions(
        make_level, h * w, shapes, visits_of, rng, progress, pool, settle,
        [(relaxing, aligning + repairing) for relaxing, aligning, repairing in costs])
    progress(1.0, "copying the pixels")
    positions = np.empty(source.shape + (2,), np.int32)
    np.divmod(source, w, out=(positions[:, :, 0], positions[:, :, 1]))
    return Rows(colours)[source], positions


def _align(level, source, radius, tick):
    """The level's copied regions slid into phase (``align_regions`` on its grid, in its own
    positions and values: neighbours ``level.step`` apart)."""
    lh, lw = level.shape
    positions = np.stack(np.divmod(level._to_level(source), lw), axis=2)
    z = level.colours.array.reshape(lh, lw, level.c)
    moved = region_shift.align_regions(z, positions, SHIFT, SWEEPS, tick, level.step,
                                       walk=True, reach=radius)
    return level._to_exemplar(moved[:, :, 0] * lw + moved[:, :, 1]).astype(np.int32)


def _lock(level, source, photo, lattice):
    """The level's copies moved into one phase of the courses' ``lattice``, the phase broken
    once where the output's size asks it (``region_shift.lock_lattice``)."""
    w = level.width
    positions = np.stack(np.divmod(source, w), axis=2)
    moved = region_shift.lock_lattice(photo, positions, lattice, level.step)
    return (moved[:, :, 0] * w + moved[:, :, 1]).astype(np.int32)


def _repair(level, source, lv, visits, shape, repair, reach, wrap, rng, tick):
    """The level's grid points near the dead ends its copies' seams make
    (``joint_repair.holes``, rendered at full resolution) relaxed again from confidence 0,
    ``REPAIR_ROUNDS`` times."""
    photo, joints = repair
    step = 2 ** lv
    for r in range(REPAIR_ROUNDS):
        positions = joint_repair.render(source, step, shape, photo.shape[:2], wrap)
        hole = joint_repair.holes(photo, positions, joints, reach, step)
        if not hole.any():
            break
        halves = np.where(hole, 0, 2 * visits).astype(np.int16)
        multigrid.relax(level, source, halves, visits, rng,
                        lambda f, *_, r=r: tick((r + f) / REPAIR_ROUNDS), lv)
    return source


def _near_ends(ends, step, sigma):
    """The positions p (bool) whose block ``[p, p + step)`` (what a level's grid point copies),
    grown by ``DEAD_END_MARGIN`` sigma on each side, holds a dead end of ``ends``."""
    m = int(np.ceil(DEAD_END_MARGIN * sigma))
    size = step + 2 * m
    return maximum_filter(ends, size, origin=m - size // 2, mode="constant")


def box_means(image, size, stride, wrap, kept=None):
    """The means of ``image`` (H, W, C) over boxes of ``size`` pixels (a power of two, at least
    ``stride``) at the lattice ``image[::stride, ::stride]``: a level's values seen at its
    scale (Wei & Levoy 2000, 3: the Gaussian pyramid's level, here a box). With ``stride`` > 1
    the s x s block means (``kept["blocks"]``, made once) are box-filtered on the lattice, the
    box then starting at the lattice point rather than centred on it.

    References
    ----------
    Wei & Levoy 2000, "Fast texture synthesis using tree-structured vector quantization", 3.

    Examples
    --------
    >>> image = np.zeros((8, 8, 1), np.float32)
    >>> image[:, ::2] = 1.0  # stripes a pixel wide: aliased by the step-2 lattice
    >>> float(image[::2, ::2].mean()), float(box_means(image, 2, 1, True)[::2, ::2].mean())
    (1.0, 0.5)
    """
    if size <= 1:
        return image[::stride, ::stride]
    if stride > 1:
        kept = {} if kept is None else kept
        if "blocks" not in kept:
            h, w = image.shape[:2]
            rows = np.add.reduceat(image, np.arange(0, h, stride), axis=0, dtype=np.float32)
            sums = np.add.reduceat(rows, np.arange(0, w, stride), axis=1, dtype=np.float32)
            n = (np.minimum(stride, h - np.arange(0, h, stride))[:, None]
                 * np.minimum(stride, w - np.arange(0, w, stride))[None, :])
            kept["blocks"] = sums / n[:, :, None].astype(np.float32)
        image, size = kept["blocks"], size // stride
    mode = "wrap" if wrap else "nearest"
    return uniform_filter1d(uniform_filter1d(image, size, axis=0, mode=mode), size, axis=1,
                            mode=mode)


def _channel_statistics(exemplar):
    """The mean colour and D, the maximal squared colour difference (the sum over channels of
    the squared ranges); reduced along rows first (a reduction along 12 M pixels of 3
    channels is slow, and in float32 inexact)."""
    h, w, c = exemplar.shape
    rows = exemplar.reshape(h, w * c)
    mean = rows.mean(axis=0, dtype=np.float64).reshape(w, c).mean(axis=0)
    spread = (rows.max(axis=0).reshape(w, c).max(axis=0).astype(np.float64)
              - rows.min(axis=0).reshape(w, c).min(axis=0))
    return mean.astype(np.float32), np.float32((spread ** 2).sum())


def lattice_stride(shape) -> int:
    """The least power of two s whose lattice ``exemplar[::s, ::s]`` has at most
    ``TABLE_ROWS`` pixels of 4 values (RGB and Q; fewer with more channels, so the joints'
    two do not make the table half as large again): the stride of the tables of levels l with
    2^l >= s. The rectified 12 MP setts (2615 x 3148) to 1024 with its joints: stride 2 -> 4,
    resident 1887 -> 852 MiB, CPU 25.6 -> 18.4 s, the outputs alike to the eye.

    References
    ----------
    Neubeck, Zalesny & Van Gool 2004, 3.1 (the levels whose tables these are).

    Examples
    --------
    >>> lattice_stride((1024, 1024, 3)), lattice_stride((3000, 4000, 3))
    (1, 4)
    """
    s = 1
    while -(-shape[0] // s) * -(-shape[1] // s) * (shape[2] + 1) > TABLE_ROWS * 4:
        s *= 2
    return s


def auto_levels(exemplar, radius):
    """Levels enough for the coarsest neighbourhood's radius (r 2^(L-1)) to span
    ``REACH_TEXELS`` texels, and at least ``MIN_LEVELS``."""
    texel = texel_size(exemplar)
    return max(MIN_LEVELS, 1 + int(np.ceil(np.log2(max(1.0, REACH_TEXELS * texel / radius)))))


def _plan(shape, width, height, params):
    """The lattice stride, its pixel count, the level count (automatic levels counted at the
    most the exemplar allows) and the levels that read whole-exemplar windows (step < stride)."""
    s = lattice_stride(shape)
    n_levels = level_count(shape, width, height, params["radius"], params["levels"] or 8)
    windows = [lv for lv in range(n_levels) if 2 ** lv < s]
    return s, -(-shape[0] // s) * -(-shape[1] // s), n_levels, windows


def _memory(shape, width, height, params):
    """The centred exemplar; then the larger of a table level's (the table, K (C + 1) floats a
    lattice pixel, its padded build, the lattice's colours, its block and box means) and a
    windows level's (the windows, C + 1 floats a pixel with their margin, and the random
    start's draw over the exemplar, 8 bytes a pixel); the output's maps (position, confidence,
    visit need, and at the end the position pairs and colours: 26 + 4 C bytes a pixel); then
    the larger of one chunk's rows (a visit) and the alignment of the largest aligned grid (its
    K border pairs' indices, 16 bytes each, its region graph, and ``region_shift.CHUNK``
    gathers of C + 4 numbers): the alignment runs between a level's visits, its peak and a
    chunk's never together (tracemalloc: 26-28 and 10-11 MiB at 64 -> 256 and 2048 x 32, 42
    and 19 MiB at 32 -> 512; their sum had put the peak 1.7-1.9x the resident)."""
    shape = feature_distance.working_shape(shape, params["joint_width"])
    h, w, c = shape
    r = params["radius"]
    k = len(disk_offsets(r))
    s, rows, n_levels, windows = _plan(shape, width, height, params)
    table = 0 if len(windows) == n_levels else rows * (k * (c + 1) + 2 * (c + 1) + 3 * c) * 4
    margin = r * 2 ** windows[0] if windows else 0
    window = (h + 2 * margin) * (w + 2 * margin) * (c + 1) * 4 + h * w * 8 if windows else 0
    maps = width * height * (26 + 4 * c)
    chunk = _Level.CHUNK * (k + params["random_candidates"]) * (4 * k * (c + 1) + 16) * 2
    grids = _aligned(width, height, n_levels, windows).values()
    align = max(grids) * (16 * k + 64) + region_shift.CHUNK * (c + 4) * 8 if grids else 0
    return h * w * c * 4 + max(table, window) + maps + max(chunk, align) + (8 << 20)


def _cost(shape, width, height, params):
    """Seconds on the reference machine (``texsynth.budget``). Per visit of an output pixel on
    each level, each candidate's disk neighbourhood compared over C + 1 values (a refining
    level: ``REFINE_VISITS`` visits, ``REFINE_PROPOSERS`` candidates, most pixels left unscored,
    its own coefficient, 1.35 times that for windows); the table of every table level;
    the passes over the whole exemplar (centring, windows, the random start's draw); per grid
    pixel of an aligned level (``_aligned``), its alignment (``SETTLE_COST``); per level, the
    relaxation's rounds (``ROUND_COST``); the coarse levels' boost and the joint repair
    (``REPAIR_PIXEL_COST``, ``REPAIR_SHARE``) where there are joints (a joint width given).
    The refining levels' and the tables' coefficients from the quiet runs of the photos
    benchmark (its 12 MP photo and its 1024 crop to 2048: 15.7 and 18.0 s) and a 1024 photo to
    4096."""
    c = shape[2]
    shape = feature_distance.working_shape(shape, params["joint_width"])
    h, w, _ = shape
    factor = COARSE_FACTOR if shape[2] > c else 1
    joints = JOINT_PIXEL_COST * h * w if factor > 1 else 0.0
    return 0.1 + sum(map(sum, _level_costs(shape, width, height, params, factor,
                                           factor > 1))) + 8e-8 * h * w + joints


def _level_costs(shape, width, height, params, factor=1,
                 repair=False) -> list[tuple[float, float, float]]:
    """:func:`_cost`'s terms of each level, finest first, also the levels' shares of the
    progress: (relaxation, alignment, joint repair) each; ``factor`` is the coarse levels'
    boost (``COARSE_FACTOR`` where there are joints), ``repair`` whether the joints are
    repaired (``REPAIR_LEVELS``: where there are joints)."""
    h, w, c = shape
    k = len(disk_offsets(params["radius"]))
    per_visit = k * (c + 1)
    s, rows, n_levels, windows = _plan(shape, width, height, params)
    aligned = _aligned(width, height, n_levels, windows)
    shapes = grid_shapes(width, height, n_levels)
    costs = []
    spacing = params["radius"] + 1                 # multigrid.relax's lattice step
    for lv, (gh, gw) in enumerate(shapes):
        boost = factor if lv >= n_levels - COARSE_LEVELS and gh * gw <= COARSE_PIXELS else 1
        if gh * gw > REFINE_PIXELS:
            t = min(params["visits"], REFINE_VISITS)
            visits = 3.0e-9 * (gh * gw * REFINE_VISITS * per_visit * REFINE_PROPOSERS
                               * (1.35 if lv in windows else 1.0))
        else:
            t = params["visits"] * boost
            seeded = 1.0 if lv == n_levels - 1 else 7 / 8  # a quarter start at half confidence
            visits = VISIT_COST * (gh * gw * t * seeded * per_visit
                                   * (RANDOM_WEIGHT * params["random_candidates"] * boost + k))
        table = 0.0 if lv in windows else TABLE_COST * rows * k * (c + 1)
        rounds = ROUND_COST * spacing ** 2 * (2 * t + 1)  # measured rounds: 1.7-3.2 spacing^2 T
        side, aspect = min(h, w) / 2 ** lv, max(gh, gw) / min(gh, gw)
        settle = ((SETTLE_COST + SETTLE_SIDE_COST / side) * (1 + aspect / SETTLE_ASPECT)
                  * aligned.get(lv, 0))
        repaired = repair and lv in REPAIR_LEVELS  # each round a rendering and its holes
        mending = (REPAIR_ROUNDS * (REPAIR_PIXEL_COST * width * height + REPAIR_SHARE * visits)
                   if repaired else 0.0)
        costs.append((visits + table + rounds, settle, mending))
    return costs


def _aligned(width, height, n_levels, windows):
    """The levels whose copies slide into phase, {level: grid pixels}: those between the
    coarsest and the finest, of at most ``ALIGN_PIXELS`` pixels, reading tables."""
    return {lv: gh * gw for lv, (gh, gw) in enumerate(grid_shapes(width, height, n_levels))
            if 0 < lv < n_levels - 1 and gh * gw <= ALIGN_PIXELS and lv not in windows}


METHOD = register(Method(
    name="multiscale_mrf",
    label="Multiscale MRF",
    description="Relax a map of exemplar positions from coarse to fine, each pixel taking the "
                "best-matching continuation of its neighbours (Paget-Longstaff with Ashikhmin "
                "candidates and confidences): structured textures, any output size",
    function=multiscale_mrf,
    params=(
        Param("radius", int, 3, "Radius r of the disk neighbourhood compared (pixels at each "
              "level)", 1, 8),
        Param("visits", int, 4, "Visits T per pixel and level; confidence grows by 1/T a visit",
              1, 16),
        Param("random_candidates", int, 2, "Random exemplar positions tried per visit besides "
              "the neighbours' continuations", 0, 32),
        Param("levels", int, 0, "Multigrid levels (capped by the exemplar and output sizes); 0: "
              "enough for the coarsest neighbourhood to span the exemplar's texels", 0, 8),
        Param("joint_width", float, 0.0, "Width (pixels) of the joints between the photo's "
              "elements (bricks, setts, blocks); 0: measured from the photo (none where it "
              "has no joint network)", 0.0, 64.0),
        Param("feature_weight", float, FEATURE_WEIGHT, "Weight of the distance to the joints "
              "in the neighbourhood match, against the colours; 0: joints not compared", 0.0,
              8.0),
        Param("exemplar_tiles", bool, False, "The exemplar itself tiles: neighbourhoods may "
              "wrap around its edges"),
    ),
    min_exemplar=3,
    memory=_memory,
    cost=_cost,
    positions=True,
))
