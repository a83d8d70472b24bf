"""Property-based sweep (Hypothesis) of every public entry point with hostile but fair input.

Random shapes, dtypes, sizes, value ranges, seeds and parameters, some of them wrong. Each call
must either give a sane result (the promised shape and dtype, finite values for finite input,
the input left untouched) or raise a ``ValueError`` raised by texsynth itself (the raising frame
is in the package) whose message is not numpy's or Python's. Examples are few and small, the
order is fixed (``derandomize``), so the file runs in well under a minute; ``deadline`` catches
a hang, not a slow run. A numpy RuntimeWarning (overflow, invalid value) fails the example.
``TEXSYNTH_FUZZ_EXAMPLES=200`` runs a longer sweep; ``--hypothesis-show-statistics`` shows the
share of examples that ran and the refusals. The properties of issue 26 (make_tileable at any
magnitude, focal_px_from_file with any path and format, the budget variables) run at least 120
examples each; the operators' follower maps are swept in tests/blender/test_fuzz_followers.py.

A property whose every example is refused would pass without testing anything, so each test
counts its calls' results and refusals and fails when the share of results is below its floor
(``@results``, with the floor's reason); the strategies draw fair input most of the time.
"""

import collections
import functools
import math
import os
import re
import traceback

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import texsynth
from texsynth import composite, cooccurrence

#: An overflow or a division by zero is garbage on its way out: an error here.
pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

PACKAGE = os.path.dirname(texsynth.__file__)
FOREIGN = ("need at least one array", "out of bounds", "could not broadcast", "division by zero",
           "zero-size array", "invalid literal", "has no attribute", "probabilities contain",
           "expected non-negative integer", "cannot be interpreted", "not supported between",
           "unsupported operand", "gufunc signature", "setting an array element",
           "truth value of an array")

#: Examples per test (``TEXSYNTH_FUZZ_EXAMPLES`` for a longer sweep).
EXAMPLES = int(os.environ.get("TEXSYNTH_FUZZ_EXAMPLES", 20))
FUZZ = settings(max_examples=EXAMPLES, deadline=20000, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

# --- strategies ----------------------------------------------------------------------------

#: Numeric dtypes besides float32 (integers taken as they are, unsigned ones scaled), and two
#: that are no image's.
FAIR_DTYPES = [np.float64, np.uint8, np.uint16, np.int32]
FOUL_DTYPES = [np.bool_, np.complex64]
RANGES = [(0.0, 1.0), (-5.0, 50.0), (1e29, 1e30), (0.0, 1e-30), (0.5, 0.5), (-1.0, 0.0)]


def mostly(good, wrong, odds: int = 6):
    """``good`` ``odds`` times out of ``odds + 1``, else ``wrong`` (Hypothesis favours the first
    of a ``sampled_from``, and treats repeated ``one_of`` branches as one)."""
    return st.sampled_from([True] * odds + [False]).flatmap(lambda ok: good if ok else wrong)


@st.composite
def images(draw, min_side=1, max_side=24, halves=False):
    """Mostly (6 in 7) a fair image: sides from ``min_side`` (at least 12, the largest default
    window) to ``max_side``, 1, 3 or 4 channels or none, float32 (3 in 4) or another numeric
    dtype, values in any of RANGES; else one flaw: a side from 1 up (often too small), 2 or 5
    channels, a dtype that is no image's, or a NaN or an infinity. ``halves``: the right half
    darker (a quarter of the left's distance from the range's low end), and mostly values of
    the first two RANGES: two classes for the segmentation (the others' colours are one)."""
    flaw = draw(mostly(st.none(), st.sampled_from(["side", "channels", "dtype", "nonfinite"])))
    fair = st.integers(max(min_side, 12), max_side)
    h, w = draw(st.integers(1, max_side) if flaw == "side" else fair), draw(fair)
    if draw(st.booleans()):
        h, w = w, h
    channels = draw(st.sampled_from([2, 5]) if flaw == "channels" else
                    st.sampled_from([3, None, 1, 4]))
    dtype = draw(st.sampled_from(FOUL_DTYPES) if flaw == "dtype" else
                 st.sampled_from([np.float32, np.float64]) if flaw == "nonfinite" else
                 mostly(st.just(np.float32), st.sampled_from(FAIR_DTYPES), odds=3))
    lo, hi = draw(mostly(st.sampled_from(RANGES[:2]), st.sampled_from(RANGES[2:])) if halves
                  else st.sampled_from(RANGES))
    rng = np.random.default_rng(draw(st.integers(0, 2**16)))
    shape = (h, w) if channels is None else (h, w, channels)
    values = lo + (hi - lo) * rng.random(shape)
    if np.dtype(dtype).kind in "ui":
        values = rng.integers(0, np.iinfo(dtype).max // 2 + 1, shape)
    if halves:
        right = values[:, w // 2:]
        right[...] = right // 4 if values.dtype.kind == "i" else lo + (right - lo) / 4
    a = values.astype(dtype)
    if flaw == "nonfinite":
        a.flat[rng.integers(a.size)] = draw(st.sampled_from([np.nan, np.inf, -np.inf]))
    return a


NO_SIZES = st.sampled_from([0, -1, 0.5, 16.0, "16", None, True, 10**6])
#: An output side: mostly (10 in 11) from 1 to 40, else no size.
SIZES = mostly(st.integers(1, 40), NO_SIZES, odds=10)
#: The smallest output side a method accepts with its default parameters (the patch).
SMALLEST_OUTPUT = {"texture_optimization": 8}
GOOD_SEEDS, NO_SEEDS = st.integers(0, 2**40), st.sampled_from([-1, 1.5, "1", None, True])
SEEDS = mostly(GOOD_SEEDS, NO_SEEDS, odds=10)
WRONG = st.sampled_from([-1, 0, 10**6, 0.5, -0.5, float("nan"), float("inf"), "x", None, True,
                         [1]])


def _good(p):
    """A value in range for parameter ``p`` (small, to stay fast)."""
    if p.type is bool:
        return st.booleans()
    if p.type is str:
        return st.sampled_from(p.choices)
    if p.type is int:
        return st.integers(int(p.min), int(min(p.max, p.min + 3)))
    return st.floats(p.min, p.max, allow_nan=False)


def _value(p):
    """A value for parameter ``p``: mostly (10 in 11) in range, sometimes not."""
    return mostly(_good(p), WRONG, odds=10)


@st.composite
def arguments(draw, smallest=1, others=()):
    """(width, height, seed, wrong): mostly (6 in 7) all fair, sides from ``smallest`` to 40;
    else ``wrong`` names the one that is not, or one of ``others`` that the test makes wrong."""
    wrong = draw(mostly(st.none(), st.sampled_from(["width", "height", "seed", *others])))
    side = st.integers(smallest, 40)
    return (draw(NO_SIZES if wrong == "width" else side),
            draw(NO_SIZES if wrong == "height" else side),
            draw(NO_SEEDS if wrong == "seed" else GOOD_SEEDS), wrong)


@st.composite
def params_for(draw, method, wrong=False, unknown=True):
    """Up to three of ``method``'s parameters, in range; ``wrong``: one of them (or of the
    others) given a wrong value, or (``unknown``) a parameter it does not have."""
    chosen = draw(st.lists(st.sampled_from(method.params), unique=True, max_size=3)) \
        if method.params else []
    values = {p.name: draw(_good(p)) for p in chosen}
    # the slow knobs of the clique model stay small unless drawn wrong
    for name, small in (("max_cliques", 3), ("sweeps", 2), ("iterations", 2)):
        if any(p.name == name for p in method.params) and name not in values:
            values[name] = small
    if wrong:
        bad = draw(st.sampled_from([p.name for p in method.params] +
                                   ["no_such_parameter"] * unknown))
        values[bad] = 1 if bad == "no_such_parameter" else draw(WRONG)
    return values


# --- the property --------------------------------------------------------------------------


def _ours(error: ValueError) -> bool:
    """Raised in texsynth's own code, with a message that is not numpy's or Python's, and
    that asks for no impossible range ("between 8 and 7 pixels")."""
    frame = traceback.extract_tb(error.__traceback__)[-1]
    message = str(error)
    empty = any(float(a) > float(b) for a, b in re.findall(
        r"between (-?\d+(?:\.\d+)?) and (-?\d+(?:\.\d+)?)", message))
    return frame.filename.startswith(PACKAGE) and not any(f in message for f in FOREIGN) \
        and not empty


def _snapshot(*arrays):
    return [np.array(a, copy=True) for a in arrays]


def _untouched(before, arrays):
    return all(np.array_equal(b, a, equal_nan=True) for b, a in zip(before, arrays, strict=True))


#: The running test's calls: how many gave a result, how many were refused (see ``results``).
TALLY = collections.Counter()
#: Why a floor is well below the share drawn: Hypothesis runs each new example and about five
#: mutations of it (under 8 other seeds, shares of 0.35-1.0 for 20 examples).
CLUSTERED = "20 examples come in clusters of about 6 (Hypothesis' mutations of each new one)"


def results(floor: float, why: str):
    """Fail the test when fewer than ``floor`` of its checked calls gave a result (not a
    refusal); ``why`` is the floor's reason, from how often its strategies draw fair input."""
    def decorate(test):
        @functools.wraps(test)
        def run(*args, **kwargs):
            TALLY.clear()
            test(*args, **kwargs)
            made, calls = TALLY["result"], TALLY["result"] + TALLY["refused"]
            assert calls and made >= floor * calls, \
                f"{made} results in {calls} calls, below the floor of {floor:.2f}: {why}"
        return run
    return decorate


def check(call, *inputs):
    """Run ``call``; return its result, or None after a ValueError of ours. Inputs untouched."""
    before = _snapshot(*inputs)
    try:
        result = call()
    except ValueError as error:
        assert _ours(error), f"foreign error: {type(error).__name__}: {error}\n" + \
            "".join(traceback.format_tb(error.__traceback__)[-3:])
        result = None
        event(f"refused: {str(error)[:40]}")
        TALLY["refused"] += 1
    else:
        event("result")
        TALLY["result"] += 1
    assert _untouched(before, inputs), "an input was modified"
    return result


def _sane(out, width, height, exemplar):
    x = np.asarray(exemplar)
    channels = 1 if x.ndim == 2 else x.shape[2]
    assert out.dtype == np.float32 and out.shape == (height, width, channels)
    assert np.isfinite(out).all()


METHODS = texsynth.methods()


@results(1 / 4, "about 3 in 4 are fair: the exemplar 6 in 7, then the other arguments 6 in 7; "
          + CLUSTERED)
@FUZZ
@given(data=st.data())
@pytest.mark.parametrize("method", METHODS, ids=[m.name for m in METHODS])
def test_synthesize(method, data):
    exemplar = data.draw(images(min_side=method.min_exemplar, halves=method.name == "composite"))
    width, height, seed, wrong = data.draw(arguments(SMALLEST_OUTPUT.get(method.name, 1),
                                                     others=["params"]))
    params = data.draw(params_for(method, wrong=wrong == "params"))
    out = check(lambda: texsynth.synthesize(exemplar, width, height, method=method.name,
                                            seed=seed, **params), exemplar)
    if out is not None:
        _sane(out, width, height, exemplar)


@results(1 / 4, "two in three: the exemplar 6 in 7, each side 10 in 11, method and mode 6 in 7; "
          + CLUSTERED)
@FUZZ
@given(exemplar=images(), width=SIZES, height=SIZES,
       method=mostly(st.sampled_from(["multiscale_mrf", "efros_leung"]), st.just("heeger_bergen")),
       mode=mostly(st.sampled_from(["column", "guided"]), st.just("other")))
def test_positions_and_stack(exemplar, width, height, method, mode):
    follower = np.asarray(exemplar)[..., :1] if np.asarray(exemplar).ndim == 3 else exemplar
    fast = {"visits": 1, "levels": 1} if method == "multiscale_mrf" else {}
    out = check(lambda: texsynth.synthesize_stack([exemplar, follower], width, height,
                                                  method=method, mode=mode, **fast), exemplar)
    if out is not None:
        assert len(out) == 2 and out[0].shape[:2] == (height, width)
        assert out[1].shape[:2] == (height, width)
    result = check(lambda: texsynth.synthesize_positions(exemplar, width, height, method=method,
                                                         **fast), exemplar)
    if result is not None:
        image, positions = result
        moved = check(lambda: texsynth.apply_positions(positions, exemplar), exemplar)
        assert moved is None or moved.shape[:2] == (height, width)


@results(1 / 4, "about 3 in 4: the fit as a synthesis, then each side 10 in 11 and sweeps 6 in 7; "
          + CLUSTERED)
@FUZZ
@given(exemplar=images(min_side=8), width=SIZES, height=SIZES, seed=SEEDS, data=st.data())
def test_clique_model(exemplar, width, height, seed, data):
    spec = {p.name: p for p in cooccurrence.model.PARAMS}
    fit_params = {name: data.draw(_value(spec[name]))
                  for name in data.draw(st.lists(st.sampled_from(
                      ["max_offset", "threshold", "levels"]), unique=True, max_size=2))}
    model = check(lambda: cooccurrence.fit(exemplar, seed=seed, max_cliques=3, **fit_params),
                  exemplar)
    if model is None:
        return
    sweeps = data.draw(mostly(st.integers(1, 2), WRONG))
    out = check(lambda: model.synthesize(width, height, seed=seed, sweeps=sweeps))
    if out is not None:
        _sane(out, width, height, exemplar)


@results(1 / 4, "about 2 in 3 are fair: as test_synthesize's, and an exemplar of two classes "
          "9 in 10; " + CLUSTERED)
@FUZZ
@given(exemplar=images(min_side=16, halves=True),
       drawn=arguments(others=["params", "labels"]), data=st.data())
def test_composite_entry_point(exemplar, drawn, data):
    width, height, seed, wrong = drawn
    # a keyword function: Python's TypeError would name an unknown parameter
    params = data.draw(params_for(texsynth.get_method("composite"), wrong=wrong == "params",
                                  unknown=False))
    labels = data.draw(st.just("wrong size") if wrong == "labels" else
                       st.sampled_from([None, "stripes"]))
    x = np.asarray(exemplar)
    if labels == "stripes":
        labels = (np.arange(x.shape[1])[None, :] * 3 // x.shape[1]).repeat(x.shape[0], 0)
    elif labels == "wrong size":
        labels = np.zeros((3, 3), np.int32)
    # an output label map of one of the exemplar's three classes, when the size is a size: the
    # other classes' cliques are still in the model
    output_labels = None
    if isinstance(labels, np.ndarray) and labels.shape == x.shape[:2] and all(
            type(v) is int and 1 <= v <= 40 for v in (width, height)):
        one = data.draw(st.sampled_from([None, 0, 1, 2]))
        output_labels = None if one is None else np.full((height, width), one, np.int32)
    result = check(lambda: composite.compose(exemplar, width, height, labels=labels,
                                             output_labels=output_labels, seed=seed,
                                             **params), exemplar)
    if result is not None:
        _sane(result.image, width, height, exemplar)


@results(1 / 4, "half the files are whole; " + CLUSTERED)
@FUZZ
@given(whole=st.booleans(), keep=st.integers(0, 5000), payload=st.binary(max_size=300))
def test_model_files(tmp_path_factory, whole, keep, payload):
    """A model file whole (half the examples), or cut at ``keep`` bytes and ``payload`` appended
    (drawn in both, so that Hypothesis' mutations of them run as often whole as damaged)."""
    data = _model().to_bytes()
    if not whole:
        data = data[:keep] + payload
    path = tmp_path_factory.mktemp("model") / "m.npz"
    path.write_bytes(data)
    loaded = check(lambda: cooccurrence.Model.load(path))
    if loaded is not None:
        _sane(loaded.synthesize(5, 4), 5, 4, np.zeros((1, 1, 3)))


_MODEL = []


def _model():
    if not _MODEL:
        rng = np.random.default_rng(1)
        _MODEL.append(cooccurrence.fit(rng.random((16, 16, 3)).astype(np.float32), max_cliques=2))
    return _MODEL[0]


@results(1 / 3, "about 3 in 4: the image 6 in 7, the contrast 10 in 11; " + CLUSTERED)
@FUZZ
@given(image=images(min_side=4), contrast=mostly(st.floats(0, 100), WRONG))
def test_segment(image, contrast):
    labels = check(lambda: texsynth.segmentation.segment(image, contrast=contrast), image)
    if labels is not None:
        assert labels.shape == np.asarray(image).shape[:2] and labels.min() == 0


NUMBERS = mostly(st.floats(0, 89), st.one_of(st.floats(-1000, 1000), WRONG))


@results(1 / 3, "about 3 in 4: slant and distance 6 in 7, any finite tilt; " + CLUSTERED)
@FUZZ
@given(slant=NUMBERS, tilt=NUMBERS, distance=mostly(st.floats(1e-3, 1000), NUMBERS))
def test_camera_pose(slant, tilt, distance):
    pose = check(lambda: texsynth.camera_pose(slant, tilt, distance))
    if pose is not None:
        assert pose.shape == (4, 4) and np.isfinite(pose).all()


@pytest.fixture(scope="module")
def plane():
    rng = np.random.default_rng(3)
    photo = rng.random((64, 64)).astype(np.float32)
    return photo, texsynth.estimate_plane(photo, method="isotropy")


@results(1 / 5, "over half: the size 3 in 4 (then each side 10 in 11), slant and focal length "
          "6 in 7; " + CLUSTERED)
@FUZZ
@given(size=mostly(st.one_of(st.none(), st.tuples(SIZES, SIZES)), SIZES), slant=NUMBERS,
       focal=st.one_of(st.none(), NUMBERS))
def test_rectify(plane, size, slant, focal):
    import dataclasses

    photo, estimate = plane
    estimate = dataclasses.replace(estimate, slant=slant, focal_px=focal)
    out = check(lambda: texsynth.rectify(photo, estimate, size=size), photo)
    if out is not None:
        assert out.dtype == np.float32 and np.isfinite(out).all()
        if isinstance(size, tuple):
            assert out.shape[:2] == (size[1], size[0])


# --- issue 26: make_tileable, focal_px_from_file, the budget variables ---------------------
# Each of these properties runs at least 120 examples (the bar).

WIDE = settings(FUZZ, max_examples=max(EXAMPLES, 120))


@st.composite
def photos(draw):
    """Mostly a float photo from 28 (the smallest a band fits) to 48 pixels a side (1, 3 or 4
    channels) at an exact power of two times ordinary values (2^-140 .. 2^120: float32's range,
    subnormals included); sometimes smaller, other channel counts, dtypes, or a NaN."""
    side = mostly(st.integers(28, 48), st.integers(1, 48), odds=8)
    h, w = draw(side), draw(side)
    channels = draw(mostly(st.sampled_from([3, None, 1, 4]), st.sampled_from([2, 5])))
    rng = np.random.default_rng(draw(st.integers(0, 2**16)))
    shape = (h, w) if channels is None else (h, w, channels)
    base = rng.random(shape).astype(np.float32)
    # brighter down the rows, so that it does not tile already (that would come back as it is)
    base = (base + np.linspace(0, 1, h, dtype=np.float32).reshape((h,) + (1,) * (base.ndim - 1))
            ) / 2
    exponent = draw(st.sampled_from([0, 0, 100, -100, 120, -140, 60, -60]))
    photo = base * np.float32(2.0) ** exponent if abs(exponent) < 127 else \
        (base.astype(np.float64) * 2.0 ** exponent).astype(np.float32)
    kind = draw(mostly(st.just("float32"), st.sampled_from(["uint8", "uint16", "nan", "inf"])))
    if kind.startswith("uint"):
        photo = (base * np.iinfo(kind).max).astype(kind)
    elif kind in ("nan", "inf"):
        photo.flat[rng.integers(photo.size)] = np.nan if kind == "nan" else np.inf
    return photo, exponent


BANDS = mostly(st.none(), st.one_of(st.integers(-2, 40), WRONG), odds=3)


@results(1 / 3, "about 3 in 5 (each side 8 in 9, channels, dtype and band mostly fair); "
          "120 examples vary little")
@WIDE
@given(drawn=photos(), band=BANDS, seed=mostly(st.integers(0, 9), SEEDS))
def test_make_tileable(drawn, band, seed):
    """A photo of huge or tiny values is made to tile exactly as its ordinary-valued copy: the
    same positions, and what the photo's pixels there give (``follow``)."""
    photo, exponent = drawn
    result = check(lambda: texsynth.make_tileable_positions(photo, band=band, seed=seed), photo)
    if result is None:
        return
    out, positions = result
    p = np.asarray(photo)
    _sane(out, p.shape[1], p.shape[0], p)
    assert np.array_equal(out, texsynth.tileable.follow(positions, p, band=band))
    if p.dtype == np.float32 and exponent:  # its ordinary copy (subnormals as rounded)
        ordinary = (p.astype(np.float64) * 2.0 ** -exponent).astype(np.float32)
        _, expected = texsynth.make_tileable_positions(ordinary, band=band, seed=seed)
        assert np.array_equal(positions, expected), "the magnitude changed the patches"


class _Fspath:
    """An os.PathLike whose ``__fspath__`` gives ``value`` (a str, bytes, or something else)."""

    def __init__(self, value):
        self.value = value

    def __fspath__(self):
        return self.value


def _exif_file(draw, folder):
    """A file of a drawn format (JPEG, TIFF, PNG, WebP in its three kinds, or garbage) with or
    without a 35 mm equivalent focal length, whole or truncated; and the focal length in
    pixels it states (None when it states none)."""
    import struct

    from _exif import FOCAL_35MM, LONG, PIXEL_X, PIXEL_Y, SHORT, jpeg, tiff, webp

    width, height = draw(st.integers(1, 5000)), draw(st.integers(1, 5000))
    f35 = draw(st.one_of(st.none(), st.integers(0, 2000)))
    exif = {} if f35 is None else {FOCAL_35MM: (SHORT, f35)}
    kind = draw(st.sampled_from(["jpeg", "tiff", "png", "VP8X", "VP8X-prefix", "VP8 ", "VP8L",
                                 "garbage"]))
    if kind == "jpeg":
        data = jpeg(width, height, {}, exif)
    elif kind == "tiff":
        data = tiff({0x0100: (LONG, width), 0x0101: (LONG, height)}, exif)
    elif kind == "png":  # a PNG without an eXIf chunk
        data = b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + b"IHDR" + struct.pack(
            ">IIBBBBB", width, height, 8, 2, 0, 0, 0)
        exif = {}
    elif kind.startswith("VP8X"):
        data = webp(width, height, {}, {**exif, PIXEL_X: (LONG, width), PIXEL_Y: (LONG, height)}
                    if exif else {}, prefix=b"Exif\x00\x00" if "prefix" in kind else b"")
    elif kind.startswith("VP8"):
        data = webp(min(width, 16383), min(height, 16383), frame=kind)
        exif = {}
    else:
        data = draw(st.binary(max_size=64))
        exif = {}
    keep = draw(mostly(st.just(len(data)), st.integers(0, len(data)), odds=4))
    path = folder / f"photo.{kind[:4].strip().lower()}"
    path.write_bytes(data[:keep])
    stated = None
    if exif and keep == len(data) and f35:
        stated = f35 / math.hypot(36.0, 24.0) * math.hypot(width, height)
        if not 0.1 <= stated / math.hypot(width, height) <= 100.0:
            stated = None  # an impossible field of view is no statement
    return path, stated


@results(1 / 2, "the path is a path 6 in 7, and a file without a focal length is a result "
          "(None); 120 examples vary little")
@WIDE
@given(data=st.data())
def test_focal_px_from_file(tmp_path_factory, data):
    """Any path of any type, any image format with or without EXIF: a positive focal length,
    None, or a ValueError of ours (the docstring's promise), and the focal length the file
    states whatever its format."""
    folder = tmp_path_factory.mktemp("exif")
    path, stated = _exif_file(data.draw, folder)
    given_path = data.draw(mostly(
        st.sampled_from([path, str(path), bytes(path), _Fspath(str(path))]),
        st.sampled_from([None, 0, 3, -1, True, 1.5, b"", "", str(folder), "a\0b", "x" * 5000,
                         [str(path)], _Fspath(None), _Fspath(3), folder / "missing.jpg"])))
    focal = check(lambda: texsynth.focal_px_from_file(given_path))
    if focal is not None:
        assert math.isfinite(focal) and focal > 0
    if given_path in (path, str(path), bytes(path)):
        assert focal == pytest.approx(stated)


BUDGETS = st.one_of(st.sampled_from(["abc", "", " ", "0", "-1", "nan", "inf", "-inf", "1e400",
                                     "1.5", "1e9", "4_000_000_000", " 2048 ", "0x10", "١٢٣",
                                     "10 GB", "None"]),
                    st.integers(-10, 10**12).map(str), st.floats().map(repr), st.text(max_size=8))


@results(1 / 5, "a budget reads as a positive number about 2 in 5, both do for synthesize "
          "about 1 in 6: a third of the calls; 120 examples vary little")
@WIDE
@given(memory=BUDGETS, seconds=BUDGETS)
def test_the_budget_variables(memory, seconds):
    """Whatever TEXSYNTH_MEMORY_BUDGET and TEXSYNTH_TIME_BUDGET hold, an entry point gives a
    result or a ValueError of ours naming a budget variable, and each budget reads as a positive
    number or as such a ValueError."""
    if "\0" in memory + seconds:
        return  # the environment cannot hold a NUL
    names = ("TEXSYNTH_MEMORY_BUDGET", "TEXSYNTH_TIME_BUDGET")
    saved = {k: os.environ.get(k) for k in names}
    os.environ.update(zip(names, (memory, seconds), strict=True))
    exemplar = np.random.default_rng(0).random((16, 16, 3)).astype(np.float32)
    try:
        calls = (lambda: texsynth.synthesize(exemplar, 8, 8), texsynth.memory_budget,
                 texsynth.budget.time_budget)
        for call in calls:
            try:
                value = call()
            except ValueError as error:
                assert _ours(error) and any(n in str(error) for n in names), str(error)
                TALLY["refused"] += 1
                continue
            TALLY["result"] += 1
            if call is calls[0]:
                _sane(value, 8, 8, exemplar)
            else:
                assert math.isfinite(value) and value > 0
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
