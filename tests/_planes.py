"""Photos of textured planes with known geometry, rendered from first principles.

A camera ray meets the plane; the plane point indexes an isotropic noise texture. Nothing of
texsynth.plane is used, so its conventions (tilt counter-clockwise from +x with y up, towards
where depth grows; camera looking along -z) are checked by the tests that use these photos.
"""

import math

import numpy as np
import scipy.ndimage as ndi

from texsynth.plane import normal_from_angles

SIZE = 256


def noise_texture(seed=0, n=512, band=(0.03, 0.2)):
    """Isotropic band-pass noise, periodic, prefiltered for cubic interpolation."""
    rng = np.random.default_rng(seed)
    f = np.hypot(np.fft.fftfreq(n)[:, None], np.fft.fftfreq(n)[None, :])
    mask = (f >= band[0]) & (f <= band[1])
    t = np.fft.ifft2(np.fft.fft2(rng.standard_normal((n, n))) * mask / np.maximum(f, 1e-9)).real
    return ndi.spline_filter(t / t.std() * 0.15, order=3, mode="grid-wrap")


def photograph(texture, slant, tilt, focal=None, size=SIZE, supersample=2, sky=None):
    """A size x size view of the textured plane; focal None: orthographic. ``sky``: the value
    of pixels whose ray misses the plane (beyond its horizon), as the benchmark's renders show
    a black world there; None: the plane's equation is used behind the camera too."""
    n = np.array([math.sin(math.radians(slant)) * math.cos(math.radians(tilt)),
                  math.sin(math.radians(slant)) * math.sin(math.radians(tilt)),
                  math.cos(math.radians(slant))])
    e1 = np.cross([0.3, 0.5, 0.8], n)  # any basis of the plane: the texture is isotropic
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    depth = 1.0 if focal is None else float(focal)  # plane units per pixel at the centre: 1
    out = np.zeros((size, size))
    offsets = (np.arange(supersample) + 0.5) / supersample - 0.5
    for dy in offsets:
        for dx in offsets:
            rows, cols = np.mgrid[0:size, 0:size].astype(float)
            x = cols + dx - (size - 1) / 2
            y = (size - 1) / 2 - (rows + dy)
            if focal is None:  # rays along -z through (x, y): the plane point above it
                point = np.stack([x, y, -depth - (n[0] * x + n[1] * y) / n[2]], -1)
            else:
                ray = np.stack([x, y, -np.full_like(x, focal)], -1)
                t = (-depth * n[2]) / (ray @ n)
                point = ray * t[..., None]
            point = point - np.array([0.0, 0.0, -depth])
            u, v = point @ e1, point @ e2
            seen = ndi.map_coordinates(texture, [v, u], order=3, mode="grid-wrap",
                                       prefilter=False)
            if sky is not None and focal is not None:
                seen = np.where(t > 0, seen, sky - 0.5)
            out += seen
    return (out / supersample ** 2 + 0.5).astype(np.float32)


def normal_error(a, b, mod180=False):
    na, nb = normal_from_angles(*a), normal_from_angles(*b)
    error = math.degrees(math.acos(min(1.0, float(na @ nb))))
    if mod180:
        flipped = normal_from_angles(b[0], b[1] + 180.0)
        error = min(error, math.degrees(math.acos(min(1.0, float(na @ flipped)))))
    return error


def spectral_slant(image):
    """Anisotropy of a photo as the slant its spectral second moments imply (degrees): the
    square root of the eigenvalue ratio of sum w w^T |I(w)|^2 is cos(slant) for an isotropic
    texture seen at that slant. A frontal noise photo of SIZE scores 13-20 deg."""
    lum = np.asarray(image, dtype=np.float64)
    lum = lum.mean(axis=2) if lum.ndim == 3 else lum
    h, w = lum.shape
    power = np.abs(np.fft.fft2((lum - lum.mean()) * np.outer(np.hanning(h), np.hanning(w)))) ** 2
    fy, fx = np.meshgrid(np.fft.fftfreq(h), np.fft.fftfreq(w), indexing="ij")
    m = [[np.sum(power * a * b) for b in (fx, fy)] for a in (fx, fy)]
    values = np.linalg.eigvalsh(np.array(m))
    return math.degrees(math.acos(math.sqrt(max(values[0], 0.0) / values[1])))


def brick_texture(seed=0, n=512, brick=(64, 24), mortar=3):
    """Periodic running-bond bricks (n x n, prefiltered like :func:`noise_texture`): each brick a
    random shade with fine noise, dark mortar joints."""
    rng = np.random.default_rng(seed)
    bw, bh = brick
    rows, cols = np.mgrid[0:n, 0:n]
    course = rows // bh
    shifted = (cols + (course % 2) * (bw // 2)) % n
    index = course * (n // bw + 1) + shifted // bw
    shade = rng.uniform(-0.12, 0.12, index.max() + 1)[index]
    joint = ((rows % bh) < mortar) | ((shifted % bw) < mortar)
    t = np.where(joint, -0.25, shade + 0.03 * rng.standard_normal((n, n)))
    return ndi.spline_filter(t, order=3, mode="grid-wrap")


def board_texture(seed=0, n=512, width=24):
    """Periodic floor boards running along x (n x n, prefiltered like :func:`noise_texture`):
    each board a random shade with grain stretched along it, dark seams between boards; no
    butt joints, so the seams are the only family of lines."""
    rng = np.random.default_rng(seed)
    rows = np.mgrid[0:n, 0:n][0]
    shade = rng.uniform(-0.12, 0.12, n // width + 1)[rows // width]
    grain = ndi.gaussian_filter(rng.standard_normal((n, n)), (0.7, 12.0), mode="wrap")
    t = np.where(rows % width < 2, -0.25, shade + 0.05 * grain / grain.std())
    return ndi.spline_filter(t, order=3, mode="grid-wrap")


def weave_texture(seed=0, n=512, cell=32):
    """Periodic basket weave (n x n, prefiltered like :func:`noise_texture`): square cells of
    parallel threads, alternately along x and along y, thin dark gaps between cells. Every pixel
    is on a thread, so the cell edges are only a little stronger than the texture around them."""
    rng = np.random.default_rng(seed)
    rows, cols = np.mgrid[0:n, 0:n]
    along_x = ((rows // cell) + (cols // cell)) % 2 == 0
    thread = cell // 4
    stripes = np.where(along_x, np.cos(np.pi * (rows % thread) / thread),
                       np.cos(np.pi * (cols % thread) / thread)) ** 2
    t = 0.2 * stripes + 0.02 * rng.standard_normal((n, n))
    t = np.where(((rows % cell) < 2) | ((cols % cell) < 2), -0.15, t)
    return ndi.spline_filter(t, order=3, mode="grid-wrap")


def rhombus_texture(seed=0, n=512, rows=32, across=64):
    """Periodic rhombic cells (n x n, prefiltered like :func:`noise_texture`): dark lines along
    x every ``rows`` pixels, and along (1, 2) (63.4 deg from x) where 2 x - y is a multiple of
    ``across``; each cell a random shade with fine noise. Two line families that are NOT
    orthogonal on the plane (as the ridges of a diamond plate or a rhombic tiling)."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:n, 0:n]
    slanted = (2 * x - y) % n
    index = (y // rows) * (n // across * 2 + 1) + slanted // across
    shade = rng.uniform(-0.12, 0.12, index.max() + 1)[index]
    joint = ((y % rows) < 3) | ((slanted % across) < 6)
    t = np.where(joint, -0.25, shade + 0.03 * rng.standard_normal((n, n)))
    return ndi.spline_filter(t, order=3, mode="grid-wrap")


def rough_brick_texture(seed=0, n=512, brick=(64, 24)):
    """Periodic running-bond bricks in colour (n x n x 3, each channel prefiltered like
    :func:`noise_texture`) as a photo shows them: mottled red bricks of random shade, grey
    mortar about as bright as the bricks (it stands out in colour more than in luminance),
    joints 2-5 pixels wide that wander by a pixel or two, a fifth of the head joints closed
    (bricks butting), and a shading gradient across the wall."""
    rng = np.random.default_rng(seed)
    bw, bh = brick
    rows, cols = np.mgrid[0:n, 0:n]
    course = rows // bh
    wobble = ndi.gaussian_filter1d(rng.standard_normal((n // bh + 1, n)), 8.0, axis=1,
                                   mode="wrap")
    bed = (rows - course * bh + 1.5 * wobble[course, cols] / wobble.std()) % bh
    shifted = (cols + (course % 2) * (bw // 2)) % n
    index = course * (n // bw + 1) + shifted // bw
    head_at = rng.uniform(-2.0, 2.0, index.max() + 1)[index]
    head_width = rng.uniform(2.0, 5.0, index.max() + 1)[index]
    head_open = rng.random(index.max() + 1)[index] > 0.2
    joint = (bed < rng.uniform(2.0, 4.0, n // bh + 1)[course]) | (
        head_open & (np.abs((shifted % bw) - bw / 2 - head_at) > bw / 2 - head_width / 2))
    mottle = ndi.gaussian_filter(rng.standard_normal((n, n)), 3.0, mode="wrap")
    shade = rng.uniform(0.75, 1.15, index.max() + 1)[index] * (1.0 + 0.4 * mottle / mottle.std()
                                                                * 0.4)
    light = 1.0 + 0.25 * np.cos(2 * np.pi * (rows + cols) / n)  # periodic, so it tiles
    red, grey = np.array([0.62, 0.30, 0.24]), np.array([0.37, 0.37, 0.36])
    grit = 0.03 * rng.standard_normal((n, n, 1))
    t = np.where(joint[..., None], grey * rng.uniform(0.85, 1.15), red * shade[..., None])
    t = (t + grit) * light[..., None]
    return np.stack([ndi.spline_filter(t[..., c], order=3, mode="grid-wrap") for c in range(3)],
                    axis=-1)
