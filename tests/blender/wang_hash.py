"""Blender's White Noise texture (3D, Color output) in numpy: Jenkins' lookup3 hash of the
input's float bits, as Cycles' ``hash_float3_to_float3`` computes it, so that a render of the
Tile Set node group can be compared with ``texsynth.norepeat.wang_tiling``."""

import numpy as np


def _rot(x, k):
    return (x << np.uint32(k)) | (x >> np.uint32(32 - k))


def _mix(a, b, c):
    for r1, r2, r3 in ((4, 6, 8), (16, 19, 4)):
        a -= c
        a ^= _rot(c, r1)
        c += b
        b -= a
        b ^= _rot(a, r2)
        a += c
        c -= b
        c ^= _rot(b, r3)
        b += a
    return a, b, c


def _final(a, b, c):
    c ^= b
    c -= _rot(b, 14)
    a ^= c
    a -= _rot(c, 11)
    b ^= a
    b -= _rot(a, 25)
    c ^= b
    c -= _rot(b, 16)
    a ^= c
    a -= _rot(c, 4)
    b ^= a
    b -= _rot(a, 14)
    c ^= b
    c -= _rot(b, 24)
    return c


def _bits(x):
    return np.ascontiguousarray(x, np.float32).view(np.uint32)


def _hash(*keys):
    """lookup3's ``hash_uint3`` (3 keys) or ``hash_uint4`` (4 keys) as a float in [0, 1]."""
    with np.errstate(over="ignore"):
        a = b = c = np.uint32((0xDEADBEEF + (len(keys) << 2) + 13) & 0xFFFFFFFF)
        a, b, c = a + _bits(keys[0]), b + _bits(keys[1]), c + _bits(keys[2])
        if len(keys) == 4:
            a, b, c = _mix(a, b, c)
            a = a + _bits(keys[3])
        return _final(a, b, c).astype(np.float32) / np.float32(0xFFFFFFFF)


def white_noise_rg(x, y, z):
    """The R and G channels of Blender's 3D White Noise at (x, y, z)."""
    x, y, z = np.broadcast_arrays(*(np.asarray(v, np.float32) for v in (x, y, z)))
    return _hash(x, y, z), _hash(x, y, z, np.ones_like(x))


def edge_colours(x, y, colours, seed=0):
    """``texsynth.norepeat.edge_colours`` as the node group computes it: White Noise's R and G
    at (x, y, seed), times ``colours``, floored."""
    r, g = white_noise_rg(x, y, seed)
    return tuple(np.minimum(np.floor(c * np.float32(colours)), colours - 1).astype(np.int64)
                 for c in (r, g))
