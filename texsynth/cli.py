"""The ``texsynth`` command: the public API on the command line, one subcommand per task.

    texsynth synthesize PHOTO -o OUT [--size 2048] [--method M] [--seed N] [--maps MAP ...]
    texsynth tile PHOTO -o OUT [--band B] [--maps MAP ...]
    texsynth estimate PHOTO [--focal-px F]          (the plane as JSON on stdout)
    texsynth rectify PHOTO -o OUT [--focal-px F]
    texsynth batch DIR_OR_MANIFEST -o OUTDIR [--operation ...] [--scheduler tcp://host:port]
    texsynth methods [--json]

Every method parameter is an option, generated from :func:`texsynth.methods` (as the Blender
panel is). The output's format follows its suffix: ``.png`` (8 or 16 bits, sRGB-encoded colour)
or ``.exr`` (float32, linear colour); colour is converted when the input's encoding differs,
unless ``--data`` says the values are data (normals, roughness). Other maps (``--maps``) always
keep their values. Progress goes to stderr: a bar with the time left on a terminal, plain lines
when piped; an error is one line naming the file or option, with the exit codes of
:data:`EXIT_CODES`.
"""

from __future__ import annotations

import argparse
import functools
import json
import logging
import math
import os
import sys
from dataclasses import asdict
from pathlib import Path

from . import batch as batch_module
from .api import synthesize as synthesize_image
from .api import synthesize_positions
from .blocks.periodic import tile_preview
from .io.files import SUFFIXES, encode, is_linear, png_bits, read_photo, write_image
from .plane import ESTIMATE_METHODS, estimate_plane, focal_px_from_file, rectify
from .positions import apply_positions
from .progress import Cancelled, TimeLeft
from .registry import get_method, methods
from .tileable import follow, make_tileable_positions

__all__ = ["main", "EXIT_CODES", "Bar"]

#: Exit status of the command, documented in every ``--help``.
EXIT_CODES = {
    0: "success",
    1: "texsynth refused or failed the work (the message names what to change), or\n"
       "       some of a batch's tasks failed",
    2: "the command line is wrong (an unknown option or a bad value)",
    3: "an input file is missing or cannot be read",
    4: "an output cannot be written",
    130: "interrupted (Ctrl+C): nothing half-written is left",
}
_EPILOG = "exit codes:\n" + "\n".join(f"  {code:<4} {text}" for code, text in EXIT_CODES.items())
_DEFAULT_METHOD = "multiscale_mrf"  # the README's "any photo, a look first"


class CliError(Exception):
    """A one-line error and the exit code that goes with it."""

    def __init__(self, message: str, code: int):
        super().__init__(message)
        self.code = code


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
        seconds = self.left.seconds(fraction)
        return "" if seconds is None or fraction >= 1.0 else f" ({_clock(seconds)} left)"

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


def _clock(seconds: float) -> str:
    seconds = int(round(seconds))
    h, rest = divmod(seconds, 3600)
    return f"{h}:{rest // 60:02d}:{rest % 60:02d}" if h else f"{rest // 60}:{rest % 60:02d}"


# --- options -------------------------------------------------------------------------------

def _size(text: str) -> tuple[int, int]:
    """``N`` (square) or ``WxH``."""
    parts = text.lower().split("x")
    try:
        values = [int(p) for p in parts]
    except ValueError:
        values = []
    if len(values) not in (1, 2) or min(values) < 1:
        raise argparse.ArgumentTypeError(f"'{text}' is not a size: give N or WIDTHxHEIGHT, "
                                         "e.g. 2048 or 2048x1024")
    return (values[0], values[-1])


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
    group.add_argument("--method", default=_DEFAULT_METHOD, choices=names, metavar="M",
                       help=f"synthesis method: {', '.join(names)} (default {_DEFAULT_METHOD}; "
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
        raise CliError(f"{flags}: not a parameter of --method {method.name} (its parameters: "
                       f"{', '.join(sorted(known)) or 'none'})", 2)
    try:
        method.resolve(given)
    except ValueError as error:
        raise CliError(f"--method {method.name}: {error}", 2) from None
    return given


def _add_output_options(parser: argparse.ArgumentParser, maps: bool) -> None:
    parser.add_argument("-o", "--output", type=Path, required=True, metavar="OUT",
                        help="output file: .png (8/16-bit) or .exr (float); its folder is made")
    parser.add_argument("--bits", type=int, choices=(8, 16), default=None,
                        help="PNG bit depth (default: the input's; 16 from EXR or float input)")
    parser.add_argument("--data", action="store_true",
                        help="the photo holds data, not colour: values are written as they are "
                             "(no sRGB <-> linear conversion between PNG and EXR)")
    parser.add_argument("--preview", action="store_true",
                        help="also write OUT_tiled.png, the result 2 x 2, to look for seams")
    if maps:
        parser.add_argument("--maps", type=Path, nargs="+", default=[], metavar="MAP",
                            help="other maps of the same material (normal, roughness...), the "
                                 "photo's size: they follow the same positions and are written "
                                 "beside OUT under their own names with OUT's suffix")


# --- the subcommands ------------------------------------------------------------------------

def _read(path: Path):
    try:
        return read_photo(path)
    except FileNotFoundError:
        raise CliError(f"{path}: no such file", 3) from None
    except (ValueError, OSError) as error:
        text = str(error)
        raise CliError(text if str(path) in text else f"{path}: {text}", 3) from None


def _check_output(path: Path, inputs: list[Path]) -> None:
    """Before reading anything: the suffix, and not an input."""
    if path.suffix.lower() not in SUFFIXES:
        raise CliError(f"-o {path}: the output's suffix must be .png or .exr", 2)
    resolved = path.resolve()
    for source in inputs:
        if source.resolve() == resolved:
            raise CliError(f"-o {path}: would overwrite the input {source}", 2)


def _make_folder(path: Path) -> None:
    """After the inputs were read, before the work: the output's folder, made and writable."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise CliError(f"{path.parent}: cannot make the folder ({error.strerror})", 4) from None
    if not os.access(path.parent, os.W_OK):
        raise CliError(f"{path.parent}: the folder cannot be written", 4)


def _map_outputs(output: Path, maps: list[Path]) -> list[Path]:
    return [output.with_name(m.stem + output.suffix) for m in maps]


def _read_maps(maps: list[Path], shape) -> list:
    found = []
    for path in maps:
        image = _read(path)
        if image.shape[:2] != shape[:2]:
            raise CliError(f"{path}: {image.shape[1]} x {image.shape[0]}, not the photo's "
                           f"{shape[1]} x {shape[0]}", 3)
        found.append(image)
    return found


def _write(path: Path, image, source: Path, args, colour: bool) -> None:
    if colour and not args.data:
        image = encode(image, from_linear=is_linear(source), to_linear=is_linear(path))
    bits = args.bits or png_bits(source)
    try:
        write_image(path, image, bits=bits)
    except OSError as error:
        raise CliError(f"{path}: cannot write ({error.strerror or error})", 4) from None
    print(f"wrote {path}")


def _write_all(args, result, positions, maps, moved_by=apply_positions) -> None:
    outputs = _map_outputs(args.output, args.maps)
    _write(args.output, result, args.photo, args, colour=True)
    if args.preview:
        preview = args.output.with_name(args.output.stem + "_tiled.png")
        _write(preview, tile_preview(result, 2, 2), args.photo, args, colour=True)
    for path, source, image in zip(outputs, args.maps, maps, strict=True):
        _write(path, moved_by(positions, image), source, args, colour=False)


def run_synthesize(args, bar: Bar) -> None:
    params = method_params(args)
    width, height = args.size
    if args.maps and not get_method(args.method).positions:
        copying = ", ".join(m.name for m in methods() if m.positions)
        raise CliError(f"--maps: --method {args.method} does not copy photo pixels, so other "
                       f"maps cannot follow it; use one of {copying}", 2)
    for path in [args.output, *_map_outputs(args.output, args.maps)]:
        _check_output(path, [args.photo, *args.maps])
    photo = _read(args.photo)
    maps = _read_maps(args.maps, photo.shape)
    _make_folder(args.output)
    if args.maps:
        result, positions = synthesize_positions(photo, width, height, method=args.method,
                                                 seed=args.seed, progress=bar, **params)
    else:
        result = synthesize_image(photo, width, height, method=args.method, seed=args.seed,
                                  progress=bar, **params)
        positions = None
    bar.close()
    _write_all(args, result, positions, maps)


def run_tile(args, bar: Bar) -> None:
    for path in [args.output, *_map_outputs(args.output, args.maps)]:
        _check_output(path, [args.photo, *args.maps])
    photo = _read(args.photo)
    maps = _read_maps(args.maps, photo.shape)
    _make_folder(args.output)
    result, positions = make_tileable_positions(photo, band=args.band, seed=args.seed,
                                                progress=bar)
    bar.close()
    _write_all(args, result, positions, maps, functools.partial(follow, band=args.band))


def _estimate(args, photo):
    focal, origin = args.focal_px, "given"
    if focal is None:
        focal = focal_px_from_file(args.photo)
        origin = "exif" if focal is not None else None
    plane = estimate_plane(photo, focal_px=focal, method=args.method)
    if origin is None:
        origin = "estimated" if plane.focal_estimated else "none (orthographic)"
    return plane, origin


def run_estimate(args, bar: Bar) -> None:
    photo = _read(args.photo)
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
    _check_output(args.output, [args.photo])
    photo = _read(args.photo)
    _make_folder(args.output)
    bar(0.0, "estimating the plane")
    plane, origin = _estimate(args, photo)
    bar(0.7, "rectifying")
    frontal = rectify(photo, plane, size=args.size)
    bar(1.0, "rectified")
    bar.close()
    print(f"slant {plane.slant:.1f} deg, tilt {plane.tilt:.1f} deg, focal "
          f"{'orthographic' if plane.focal_px is None else f'{plane.focal_px:.0f} px'} "
          f"({origin}), confidence {plane.confidence:.2f}", file=sys.stderr)
    _write(args.output, frontal, args.photo, args, colour=True)


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
        raise CliError(f"--workers: at least 1 worker process, got {args.workers}", 2)
    defaults = batch_module.Defaults(
        operations=tuple(args.operation or ("synthesize",)), method=args.method,
        size=args.size, seed=args.seed, params=params, band=args.band, format=args.format,
        bits=args.bits, data=args.data)
    try:
        jobs = batch_module.plan(args.source, args.output, defaults)
    except FileNotFoundError as error:
        raise CliError(str(error), 3) from None
    except ValueError as error:
        raise CliError(str(error), 2) from None
    try:
        summary = batch_module.run(jobs, scheduler=args.scheduler, workers=args.workers,
                                   progress=bar)
    except ImportError as error:
        raise CliError(f"batch needs Dask: pip install \"texsynth[batch]\" ({error})", 1) from None
    except ConnectionError as error:
        raise CliError(f"--scheduler {error}", 1) from None
    bar.close()
    print(summary.line())
    for failure in summary.failed:
        print(f"failed: {failure}", file=sys.stderr)
    if summary.failed:
        raise CliError(f"{len(summary.failed)} of {summary.total} tasks failed", 1)


# --- the parser ------------------------------------------------------------------------------

def build_parser() -> argparse.ArgumentParser:
    """The whole command line (``texsynth --help``; ``texsynth COMMAND --help`` for each)."""
    formatter = argparse.RawDescriptionHelpFormatter
    parser = argparse.ArgumentParser(
        prog="texsynth", formatter_class=formatter, epilog=_EPILOG,
        description="Seamless (tileable) textures from photos: example-based texture synthesis.")
    parser.add_argument("--version", action="version", version=f"texsynth {batch_module.version()}")
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
        if name == "rectify":
            sub.add_argument("--size", type=_size, default=None, metavar="N|WxH",
                             help="resample the frontal view to this size (default: the "
                                  "photo's resolution at its centre)")
            _add_output_options(sub, maps=False)

    sub = command("batch", run_batch, batch_module.__doc__.split("\n\n")[0])
    sub.add_argument("source", type=Path, metavar="DIR|MANIFEST",
                     help="a folder (every image file in it) or a manifest .csv/.tsv "
                          "(columns: photo, maps, operation, method, size, seed, params)")
    sub.add_argument("-o", "--output", type=Path, required=True, metavar="OUTDIR",
                     help="output folder (made); outputs are named after photo, operation "
                          "and parameters")
    sub.add_argument("--operation", action="append", choices=batch_module.OPERATIONS,
                     help="what to do with each photo (repeat for several; default synthesize)")
    sub.add_argument("--size", type=_size, default=(1024, 1024), metavar="N|WxH",
                     help="synthesized size (default 1024)")
    sub.add_argument("--band", type=int, default=None, help="tile: band width (default side/8)")
    sub.add_argument("--format", choices=("png", "exr"), default=None,
                     help="output format (default: EXR from EXR input, else PNG)")
    sub.add_argument("--bits", type=int, choices=(8, 16), default=None,
                     help="PNG bit depth (default: the input's)")
    sub.add_argument("--data", action="store_true",
                     help="the photos hold data: no sRGB <-> linear conversion")
    sub.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                     help="a running `dask scheduler` (default: a local cluster)")
    sub.add_argument("--workers", type=int, default=None,
                     help="local cluster: worker processes (default: one per 4 cores, at "
                          "least one; each task uses every core of its machine)")
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
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.getLogger("exifread").setLevel(logging.ERROR)  # "no EXIF" is an answer, not news
    bar = Bar(quiet=args.quiet)
    try:
        args.run(args, bar)
    except CliError as error:
        bar.close()
        print(f"texsynth: error: {error}", file=sys.stderr)
        return error.code
    except Cancelled:
        bar.close()
        print("texsynth: cancelled; nothing written", file=sys.stderr)
        return 130
    except KeyboardInterrupt:
        bar.close()
        print("texsynth: interrupted; nothing half-written is left", file=sys.stderr)
        return 130
    except ValueError as error:
        bar.close()
        print(f"texsynth: error: {error}", file=sys.stderr)
        return 1
    except MemoryError:
        bar.close()
        print("texsynth: error: out of memory; try a smaller --size", file=sys.stderr)
        return 1
    return 0
