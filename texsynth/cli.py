"""The ``texsynth`` command: the public API on the command line, one subcommand per task.

    texsynth synthesize PHOTO -o OUT [--size 2048] [--method M] [--seed N] [--maps MAP ...]
    texsynth tile PHOTO -o OUT [--band B] [--maps MAP ...]
    texsynth estimate PHOTO [--focal-px F]          (the plane as JSON on stdout)
    texsynth rectify PHOTO -o OUT [--focal-px F]
    texsynth material PHOTO -o DIR [--size N] [--mask MASK] [--corners X1,Y1,...] [--skip S]
    texsynth batch DIR_OR_MANIFEST -o OUTDIR [--operation ...] [--scheduler tcp://host:port]
    texsynth methods [--json]

Every method parameter is an option, generated from :func:`texsynth.methods` (as the Blender
panel is). Photos are read upright (EXIF orientation); ``--in-size`` resamples them first. The
output's format follows its suffix: ``.png`` and ``.tif`` (8 or 16 bits), ``.jpg`` (8 bits) with
sRGB-encoded colour, or ``.exr`` (float32, linear colour); colour is converted when the input's
encoding differs, unless ``--data`` says the values are data (normals, roughness). Other maps
(``--maps``) always keep their values. Every job goes through :mod:`texsynth.jobs`: the plan
is checked before any file is read and every input and value before any work, so nothing is
lost. The predicted time and memory, then progress, go to stderr: a bar with the time left on
a terminal, plain lines when piped; an error is one line naming the file or option, with the
exit codes of :data:`EXIT_CODES`.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from dataclasses import asdict
from pathlib import Path

from . import batch as batch_module
from .budget import forecast_line
from .io.files import encode, is_linear
from .jobs import (
    DEFAULT_METHOD,
    EXIT_CODES,
    Job,
    JobError,
    OutputError,
    RefusedError,
    UsageError,
    check_folder,
    check_plan,
    default_bits,
    execute,
    execute_material,
    material_job,
    parse_in_size,
    parse_size,
    preflight,
    read_input,
    remove_made_folders,
    version,
    write_outputs,
)
from .material.pipeline import STEPS
from .plane import (
    ESTIMATE_METHODS,
    estimate_plane,
    focal_px_from_file,
    from_rectangle,
    rectify,
    verdict,
)
from .progress import Cancelled, TimeLeft
from .registry import get_method, methods
from .validation import BudgetError

__all__ = ["main", "EXIT_CODES", "Bar"]

_EPILOG = ("existing files: an output replaces a file of its name only when it is complete "
           "(written\nbeside it, then renamed); an input is never written over, and outputs "
           "that would\nbe one file are refused before any work.\n\nexit codes:\n"
           + "\n".join(f"  {code:<4} {text}" for code, text in EXIT_CODES.items()))


class _Parser(argparse.ArgumentParser):
    """argparse with its errors as one line (``UsageError``), not the usage block."""

    def error(self, message):
        raise UsageError(f"{message} (see '{self.prog} --help')")


class Bar:
    """Progress on stderr: ``progress(fraction, message)`` as texsynth calls it.

    On a terminal one line redrawn in place, a bar with the percentage and the time left
    (:class:`texsynth.progress.TimeLeft`, from ``predicted`` seconds when given); piped, a plain
    line each time the message changes or another tenth is done, so logs stay short.

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> bar = Bar(out, tty=False)
    >>> bar(0.0, "start"); bar(0.05, "step 1"); bar(1.0, "done"); bar.close()
    >>> out.getvalue().splitlines()
    ['  0% start', '100% done']
    """

    def __init__(self, stream=None, tty: bool | None = None, quiet: bool = False,
                 predicted: float | None = None):
        self.stream = sys.stderr if stream is None else stream
        self.tty = self.stream.isatty() if tty is None else tty
        self.quiet = quiet
        self.left = TimeLeft(predicted)
        self.last = (-1, None)
        self.drawn = False

    def __call__(self, fraction: float, message: str = "") -> None:
        if self.quiet:
            return
        fraction = min(max(float(fraction), 0.0), 1.0)
        if self.tty:
            self._draw(fraction, message)
            return
        tenth = int(fraction * 10)
        if tenth > self.last[0]:
            self.stream.write(f"{fraction:4.0%}{self._left(fraction)} {message}\n")
            self.stream.flush()
            self.last = (tenth, message)

    def _left(self, fraction: float) -> str:
        told = self.left.text(fraction)
        return f" ({told})" if told else ""

    def _draw(self, fraction: float, message: str) -> None:
        filled = int(round(fraction * 24))
        left = self._left(fraction) or " (--:-- left)"
        line = f"[{'#' * filled}{'-' * (24 - filled)}] {fraction:4.0%}{left}  {message}"
        self.stream.write(f"\r{line[:100]:100s}")
        self.stream.flush()
        self.drawn = True

    def close(self) -> None:
        """End the redrawn line (a terminal's next output starts on a fresh one)."""
        if self.drawn:
            self.stream.write("\n")
            self.stream.flush()
            self.drawn = False


# --- options -------------------------------------------------------------------------------

def _size(text: str) -> tuple[int, int]:
    """``N`` (square) or ``WxH``, for argparse."""
    try:
        return parse_size(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def _in_size(text: str) -> tuple[int, int]:
    """``N`` (the longer side, aspect kept: height 0) or ``WxH``, for argparse."""
    try:
        return parse_in_size(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def _param_help(name: str) -> tuple[type, str, tuple]:
    """The option's type, its help (each method that has it, with default and range), choices."""
    owners = [(m, m.param(name)) for m in methods() if name in {p.name for p in m.params}]
    types = {p.type for _, p in owners}
    kind = owners[0][1].type if len(types) == 1 else float
    parts = []
    for m, p in owners:
        bounds = "" if p.min is None else f", {p.min:g} to {p.max:g}"
        parts.append(f"{m.name}: {p.description.rstrip('.')} (default {p.default}{bounds})")
    choices = tuple(c for _, p in owners for c in p.choices)
    return kind, "; ".join(parts).replace("%", "%%"), tuple(dict.fromkeys(choices))


def _add_method_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group(
        "method", "the synthesis method and its parameters (texsynth.methods(); each "
        "parameter applies to the methods named in its help, defaults are the method's own)")
    names = [m.name for m in methods()]
    group.add_argument("--method", default=DEFAULT_METHOD, choices=names, metavar="M",
                       help=f"synthesis method: {', '.join(names)} (default {DEFAULT_METHOD}; "
                            "`texsynth methods` describes them)")
    group.add_argument("--seed", type=int, default=0,
                       help="random seed: same inputs and seed, the same bits (default 0)")
    names = dict.fromkeys(p.name for m in methods() for p in m.params)
    for name in names:
        kind, text, choices = _param_help(name)
        flag = "--" + name.replace("_", "-")
        if kind is bool:
            group.add_argument(flag, dest=f"param_{name}", action=argparse.BooleanOptionalAction,
                               default=None, help=text)
        elif kind is str:
            group.add_argument(flag, dest=f"param_{name}", choices=choices, default=None,
                               help=text)
        else:
            group.add_argument(flag, dest=f"param_{name}", type=kind, default=None,
                               metavar=name.upper(), help=text)


def method_params(args) -> dict:
    """The method parameters given on the command line, checked against the chosen method."""
    given = {k[len("param_"):]: v for k, v in vars(args).items()
             if k.startswith("param_") and v is not None}
    method = get_method(args.method)
    known = {p.name for p in method.params}
    stray = sorted(set(given) - known)
    if stray:
        flags = ", ".join("--" + s.replace("_", "-") for s in stray)
        raise UsageError(f"{flags}: not a parameter of --method {method.name} (its parameters: "
                         f"{', '.join(sorted(known)) or 'none'})")
    try:
        method.resolve(given)
    except ValueError as error:
        raise UsageError(f"--method {method.name}: {error}") from None
    return given


def _add_output_options(parser: argparse.ArgumentParser, maps: bool) -> None:
    parser.add_argument("-o", "--output", type=Path, required=True, metavar="OUT",
                        help="output file, its format by its suffix: .png (8/16-bit), .exr "
                             "(float, linear), .jpg (8-bit, quality 95), .tif (8/16-bit); its "
                             "folder is made")
    parser.add_argument("--bits", type=int, choices=(8, 16), default=None,
                        help="PNG bit depth (default: the input's; 16 from EXR or float input)")
    parser.add_argument("--data", action="store_true",
                        help="the photo holds data, not colour: values are written as they are "
                             "(no sRGB <-> linear conversion between PNG and EXR)")
    parser.add_argument("--preview", action="store_true",
                        help="also write OUT_tiled.png, the result 2 x 2, to look for seams")
    parser.add_argument("--in-size", type=_in_size, default=None, metavar="N|WxH",
                        help="resample the photo (and its maps) to this size first: N makes its "
                             "longer side N, keeping its aspect (a 12 MP photo's features are "
                             "large at 2048; --in-size 1024 halves them)")
    if maps:
        parser.add_argument("--maps", type=Path, nargs="+", default=[], metavar="MAP",
                            help="other maps of the same material (normal, roughness...), the "
                                 "photo's size: they follow the same positions and are written "
                                 "beside OUT under their own names with OUT's suffix")


# --- the subcommands ------------------------------------------------------------------------

def _file_job(args, operation: str, **fields) -> tuple[Job, float]:
    """The command line's one job, checked as a batch's are (``texsynth.jobs``), and its
    predicted seconds (the predicted time and memory are printed before the work)."""
    out = args.output
    job = Job(photo=str(args.photo), maps=tuple(map(str, args.maps)), operation=operation,
              outputs=(str(out), *(str(out.with_name(m.stem + out.suffix)) for m in args.maps)),
              seed=args.seed, bits=args.bits or default_bits(args.photo), data=args.data,
              preview=str(out.with_name(out.stem + "_tiled.png")) if args.preview else None,
              in_size=args.in_size, **fields)
    check_plan([job])
    ((seconds, peak),) = preflight([job])
    if not args.quiet:
        print(forecast_line(seconds, peak), file=sys.stderr)
    return job, seconds


def _execute(planned: tuple[Job, float], bar: Bar) -> None:
    job, seconds = planned
    bar.left = TimeLeft(seconds)  # the clock starts with the work
    written = execute(job, progress=bar)
    bar.close()
    for path in written:
        print(f"wrote {path}")


def run_synthesize(args, bar: Bar) -> None:
    params = method_params(args)
    width, height = args.size
    _execute(_file_job(args, "synthesize", method=args.method, width=width, height=height,
                       params=tuple(sorted(params.items()))), bar)


def run_tile(args, bar: Bar) -> None:
    _execute(_file_job(args, "tile", band=args.band), bar)


def _estimate(args, photo):
    focal, origin = args.focal_px, "given"
    if focal is None:
        focal = focal_px_from_file(args.photo)
        origin = "exif" if focal is not None else None
    if args.corners is None:
        plane = estimate_plane(photo, focal_px=focal, method=args.method)
    else:  # the user's rectangle: x1,y1,...,x4,y4 in pixels, x right, y down
        try:
            xy = [float(v) for v in args.corners.split(",")]
        except ValueError:
            xy = []
        if len(xy) != 8:
            raise UsageError(f"--corners must be 8 numbers x1,y1,x2,y2,x3,y3,x4,y4 (pixels, "
                             f"in order around the rectangle), got {args.corners!r}")
        plane = from_rectangle([xy[i:i + 2] for i in range(0, 8, 2)], photo.shape[:2],
                               focal)
    if origin is None:
        origin = "estimated" if plane.focal_estimated else "none (orthographic)"
    judged = verdict(plane)
    if judged.guess:  # said even with -q: a guess applied as it is warps the photo
        print(f"texsynth: warning: the plane is a guess: {'; '.join(judged.reasons)}; "
              "--corners takes it from a rectangle on it", file=sys.stderr)
    return plane, origin


def run_estimate(args, bar: Bar) -> None:
    photo = read_input(args.photo)
    bar(0.0, "estimating the plane")
    plane, origin = _estimate(args, photo)
    bar(1.0, "estimated")
    bar.close()
    record = asdict(plane)
    record.update(photo=str(args.photo), focal_from=origin)
    print(json.dumps(record, indent=2, default=_json_default))


def _json_default(value):
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    raise TypeError(type(value).__name__)


def run_rectify(args, bar: Bar) -> None:
    job = Job(photo=str(args.photo), outputs=(str(args.output),), operation="rectify")
    check_plan([job])
    photo = read_input(args.photo)
    check_folder(args.output.parent)
    bar(0.0, "estimating the plane")
    plane, origin = _estimate(args, photo)
    bar(0.7, "rectifying")
    frontal = rectify(photo, plane, size=args.size)
    bar(1.0, "rectified")
    bar.close()
    print(f"slant {plane.slant:.1f} deg, tilt {plane.tilt:.1f} deg, focal "
          f"{'orthographic' if plane.focal_px is None else f'{plane.focal_px:.0f} px'} "
          f"({origin}), confidence {plane.confidence:.2f}", file=sys.stderr)
    if not args.data:
        frontal = encode(frontal, from_linear=is_linear(args.photo),
                         to_linear=is_linear(args.output))
    write_outputs([(str(args.output), frontal)], args.bits or default_bits(args.photo))
    print(f"wrote {args.output}")


def _corner_values(text: str | None):
    """``--corners``: 8 numbers x1,y1,...,x4,y4, or :class:`UsageError`."""
    if text is None:
        return None
    try:
        xy = [float(v) for v in text.split(",")]
    except ValueError:
        xy = []
    if len(xy) != 8:
        raise UsageError(f"--corners must be 8 numbers x1,y1,x2,y2,x3,y3,x4,y4 (pixels, in order "
                         f"around the rectangle), got {text!r}")
    return xy


def run_material(args, bar: Bar) -> None:
    fmt = args.format or ("exr" if is_linear(args.photo) else "png")
    job = material_job(str(args.photo), args.output, mask=args.mask, size=args.size,
                       corners=_corner_values(args.corners), skip=args.skip or (),
                       method=args.method, seed=args.seed,
                       bits=args.bits or default_bits(args.photo), fmt=fmt)
    check_plan([job])
    # the user named a folder, not these files: one already there is theirs (write_material's rule)
    there = [output for output in job.outputs if Path(output).exists()]
    if there:
        raise OutputError(f"{there[0]} exists; nothing was written (choose another folder, or "
                          "remove the files)")
    ((seconds, peak),) = preflight([job])
    if not args.quiet:
        print(forecast_line(seconds, peak), file=sys.stderr)
    bar.left = TimeLeft(seconds)
    written, steps = execute_material(job, progress=bar)
    bar.close()
    for line in steps:  # said even with -q: a skipped rectify changes what the user gets
        print(line, file=sys.stderr)
    for path in written:
        print(f"wrote {path}")


def run_methods(args, bar: Bar) -> None:
    if args.json:
        listing = [{"name": m.name, "label": m.label, "description": m.description,
                    "positions": m.positions,
                    "params": [{"name": p.name, "type": p.type.__name__, "default": p.default,
                                "min": p.min, "max": p.max, "choices": list(p.choices),
                                "description": p.description} for p in m.params]}
                   for m in methods()]
        print(json.dumps(listing, indent=2))
        return
    for m in methods():
        print(f"{m.name}: {m.description}")
        for p in m.params:
            print(f"    --{p.name.replace('_', '-')} (default {p.default}): {p.description}")


def run_batch(args, bar: Bar) -> None:
    params = method_params(args)
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers: at least 1 worker process, got {args.workers}")
    if args.band is not None and args.band < 1:
        raise UsageError(f"--band: a width in pixels of at least 1, got {args.band}")
    if args.scheduler is not None:
        try:
            batch_module.scheduler_address(args.scheduler)
        except ValueError as error:
            raise UsageError(f"--{error}") from None
    defaults = batch_module.Defaults(
        operations=tuple(args.operation or ("synthesize",)), method=args.method,
        size=args.size, seed=args.seed, params=params, band=args.band, format=args.format,
        bits=args.bits, data=args.data, in_size=args.in_size)
    jobs = batch_module.plan(args.source, args.output, defaults)
    if not args.quiet:  # as the single command: before any work (tasks already done: less)
        seconds, peak = batch_module.forecast(jobs, args.workers,
                                              local=args.scheduler is None)
        print(f"{forecast_line(seconds, peak)} for {len(jobs)} tasks", file=sys.stderr)
    try:
        summary = batch_module.run(jobs, scheduler=args.scheduler, workers=args.workers,
                                   progress=bar)
    except ImportError as error:
        raise JobError(f"batch needs Dask: pip install \"texsynth[batch]\" ({error})") from None
    except ConnectionError as error:
        raise UsageError(f"--scheduler {error}") from None
    bar.close()
    print(summary.line())
    for failure in summary.failed:
        print(f"failed: {failure}", file=sys.stderr)
    if summary.failed:
        raise JobError(f"{len(summary.failed)} of {summary.total} tasks failed")


# --- the parser ------------------------------------------------------------------------------

def build_parser() -> argparse.ArgumentParser:
    """The whole command line (``texsynth --help``; ``texsynth COMMAND --help`` for each)."""
    formatter = argparse.RawDescriptionHelpFormatter
    parser = _Parser(
        prog="texsynth", formatter_class=formatter, epilog=_EPILOG,
        description="Seamless (tileable) textures from photos: example-based texture synthesis.")
    parser.add_argument("--version", action="version", version=f"texsynth {version()}")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress output")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    def command(name, run, text):
        sub = commands.add_parser(name, help=text, description=text, epilog=_EPILOG,
                                  formatter_class=formatter)
        sub.set_defaults(run=run)
        return sub

    sub = command("synthesize", run_synthesize,
                  "a new seamless texture of any size from PHOTO")
    sub.add_argument("photo", type=Path, metavar="PHOTO", help="the example: PNG, EXR (JPEG, "
                     "TIFF, WebP with Pillow installed)")
    sub.add_argument("--size", type=_size, default=(1024, 1024), metavar="N|WxH",
                     help="output size in pixels (default 1024)")
    _add_output_options(sub, maps=True)
    _add_method_options(sub)

    sub = command("tile", run_tile, "PHOTO itself made tileable (its size; only a band across "
                  "its edges changes)")
    sub.add_argument("photo", type=Path, metavar="PHOTO")
    sub.add_argument("--band", type=int, default=None,
                     help="width in pixels of the re-synthesized band (default: side / 8)")
    sub.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    _add_output_options(sub, maps=True)

    for name, run, text in (
            ("estimate", run_estimate, "the slant and tilt of the textured plane in PHOTO, "
             "as JSON on stdout (focal length from --focal-px, else the EXIF, else estimated)"),
            ("rectify", run_rectify, "the frontal view of the textured plane in PHOTO")):
        sub = command(name, run, text)
        sub.add_argument("photo", type=Path, metavar="PHOTO")
        sub.add_argument("--focal-px", type=float, default=None,
                         help="focal length in pixels (default: from the EXIF, else estimated)")
        sub.add_argument("--method", choices=ESTIMATE_METHODS, default="auto",
                         help="auto: perspective and lines; isotropy: orthographic, tilt mod 180")
        sub.add_argument("--corners", default=None, metavar="X1,Y1,...,X4,Y4",
                         help="the plane from a rectangle on it instead: its four corners in "
                              "order around it (pixels, x right, y down); the focal length as "
                              "above, else from the rectangle's vanishing points")
        if name == "rectify":
            sub.add_argument("--size", type=_size, default=None, metavar="N|WxH",
                             help="resample the frontal view to this size (default: the "
                                  "photo's resolution at its centre)")
            _add_output_options(sub, maps=False)

    sub = command("material", run_material,
                  "a tiling material from a photo of a surface: rectified, healed, de-lit, "
                  "made to tile, with normal (OpenGL), displacement, roughness and ambient "
                  "occlusion maps, named as ambientCG's (Node Wrangler's Ctrl+Shift+T loads them)")
    sub.add_argument("photo", type=Path, metavar="PHOTO")
    sub.add_argument("-o", "--output", type=Path, required=True, metavar="DIR",
                     help="output folder (made): PHOTO_Color, _NormalGL, _Displacement, "
                          "_Roughness, _AmbientOcclusion")
    sub.add_argument("--size", type=_size, default=None, metavar="N|WxH",
                     help="synthesize the material to this size (default: the photo itself, "
                          "rectified, made to tile at its own size)")
    sub.add_argument("--mask", type=Path, default=None, metavar="MASK",
                     help="an image of the photo's size, white where the photo is to be "
                          "healed (a sign, a stain); a photo's varying alpha is healed too")
    sub.add_argument("--corners", default=None, metavar="X1,Y1,...,X4,Y4",
                     help="rectify by a rectangle on the surface: its four corners in order "
                          "around it (pixels, x right, y down), not by the plane estimate")
    sub.add_argument("--skip", nargs="+", choices=STEPS, default=None,
                     metavar="STEP", help=f"leave steps out: {', '.join(STEPS)}")
    sub.add_argument("--method", default=DEFAULT_METHOD, choices=[m.name for m in methods()],
                     metavar="M", help=f"synthesis method for --size (default {DEFAULT_METHOD})")
    sub.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    sub.add_argument("--bits", type=int, choices=(8, 16), default=None,
                     help="PNG bit depth (default: the photo's)")
    sub.add_argument("--format", choices=("png", "exr"), default=None,
                     help="file format (default: EXR from EXR, else PNG)")

    sub = command("batch", run_batch, batch_module.__doc__.split("\n\n")[0])
    sub.add_argument("source", type=Path, metavar="DIR|MANIFEST",
                     help="a folder (every image file in it) or a manifest .csv/.tsv "
                          "(columns: photo, maps, operation, method, size, seed, params)")
    sub.add_argument("-o", "--output", type=Path, required=True, metavar="OUTDIR",
                     help="output folder (made); outputs are named after photo, operation "
                          "and parameters. An output whose key and bytes match (a done task) "
                          "is kept; any other file of its name is replaced when the new one is "
                          "complete")
    sub.add_argument("--operation", action="append", choices=batch_module.OPERATIONS,
                     help="what to do with each photo (repeat for several; default synthesize)")
    sub.add_argument("--size", type=_size, default=(1024, 1024), metavar="N|WxH",
                     help="synthesized size (default 1024)")
    sub.add_argument("--band", type=int, default=None, help="tile: band width (default side/8)")
    sub.add_argument("--in-size", type=_in_size, default=None, metavar="N|WxH",
                     help="resample each photo (and its maps) to this size first (N: the "
                          "longer side, aspect kept)")
    sub.add_argument("--format", choices=("png", "exr", "jpg", "tif"), default=None,
                     help="output format (default: EXR from EXR input, else PNG)")
    sub.add_argument("--bits", type=int, choices=(8, 16), default=None,
                     help="PNG bit depth (default: the input's)")
    sub.add_argument("--data", action="store_true",
                     help="the photos hold data: no sRGB <-> linear conversion")
    sub.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                     help="a running `dask scheduler` (default: a local cluster)")
    sub.add_argument("--workers", type=int, default=None,
                     help="local cluster: worker processes (default: one per core, at most one "
                          "per task, as many as the memory budget holds)")
    _add_method_options(sub)

    sub = command("methods", run_methods, "the synthesis methods and their parameters")
    sub.add_argument("--json", action="store_true", help="as JSON")
    return parser


def main(argv=None) -> int:
    """Run the command line; returns the exit status (:data:`EXIT_CODES`).

    Examples
    --------
    >>> main(["methods"])  # doctest: +ELLIPSIS
    heeger_bergen: ...
    0
    """
    bar = Bar(quiet=True)
    try:
        args = build_parser().parse_args(argv)
        bar = Bar(quiet=args.quiet)
        _check_bits(args)
        args.run(args, bar)
    except (Cancelled, KeyboardInterrupt):
        return _fail(bar, "interrupted; nothing half-written is left", 130)
    except JobError as error:
        return _fail(bar, f"error: {error}", error.code)
    except BudgetError as error:
        return _fail(bar, f"error: {error}", RefusedError.code)
    except ValueError as error:
        return _fail(bar, f"error: {error}", JobError.code)
    except MemoryError:
        return _fail(bar, "error: out of memory; try a smaller --size", JobError.code)
    except Exception as error:  # a bug: one line, the whole story with TEXSYNTH_DEBUG=1
        if os.environ.get("TEXSYNTH_DEBUG"):
            raise
        return _fail(bar, f"internal error: {type(error).__name__}: {error} (TEXSYNTH_DEBUG=1 "
                     "shows where; please report it)", JobError.code)
    return 0


def _check_bits(args) -> None:
    """``--bits 16`` with a JPEG output: refused (a JPEG holds 8 bits a sample; without
    ``--bits`` a 16-bit photo's JPEG is 8 bits, as documented)."""
    if getattr(args, "bits", None) != 16:
        return
    out = getattr(args, "output", None)
    fmt = getattr(args, "format", None)
    jpeg = fmt in ("jpg", "jpeg") if fmt else out is not None and \
        Path(out).suffix.lower() in (".jpg", ".jpeg")
    if jpeg:
        raise UsageError("--bits 16: a JPEG holds 8 bits a sample; write .png or .tif for 16")


def _fail(bar: Bar, text: str, code: int) -> int:
    bar.close()
    remove_made_folders()
    print(f"texsynth: {text}", file=sys.stderr)
    return code
