"""Photos in, files out: the one path of the ``texsynth`` command and of its batches.

A :class:`Job` is one photo (and the other maps of its material) through one operation into
named files. The command line makes one job, :mod:`texsynth.batch` one per photo and
operation of a folder or a manifest; every check is written here, once, and runs in this order:

1. :func:`check_plan`, before any file is opened: every output's format is known, no output is
   an input (by path, link or inode), no two outputs are one file, and no output would be taken
   as a photo of the same folder on the next run;
2. :func:`preflight`, before any work: every input is a readable image of the right size
   (headers alone), the sizes, seeds and parameters are valid, the run fits the time and
   memory budgets (``api.check``, ``tileable.check``), and every output folder takes a file;
3. :func:`execute`: read, synthesize or tile, check that every result is finite, then write
   every output to a temporary file and rename them all only when all are complete, so a
   failure leaves no partial set;
4. :func:`run_job`, a batch's task: :func:`execute` unless the outputs are already there,
   read back with the bytes their key records (:func:`key`, :func:`is_done`).

Every refusal is a :class:`JobError` with one line naming the file, manifest row, column or
option, and an exit status (:data:`EXIT_CODES`) that means one thing.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache
from importlib import metadata
from pathlib import Path

import numpy as np

from . import api, budget, tileable, validation
from .blocks.periodic import tile_preview
from .blocks.resample import resample
from .io.files import (
    TEMP_PREFIX,
    ImageReadError,
    ImageWriteError,
    encode,
    image_size,
    is_linear,
    output_format,
    png_bits,
    read_photo,
    temp_prefix,
    write_images,
)
from .material import pipeline as material
from .material.heal import check_mask
from .plane import focal_px_from_file
from .positions import apply_positions
from .registry import get_method, methods

__all__ = ["DEFAULT_METHOD", "EXIT_CODES", "OPERATIONS", "PHOTO_SUFFIXES", "KEYS", "JobError",
           "UsageError", "InputError", "OutputError", "RefusedError", "Job", "parse_size",
           "parse_in_size", "check_plan", "preflight", "check_folder", "read_input",
           "default_bits", "in_shape", "execute", "write_outputs", "run_job", "key", "is_done",
           "version", "code_digest", "material_job", "execute_material"]

#: Exit status of the command line, each with one meaning.
EXIT_CODES = {
    0: "success",
    1: "texsynth refused or failed the work (the message says what to change), or some of a "
       "batch's tasks failed",
    2: "the command line or a manifest is wrong (an option, a value, outputs that collide)",
    3: "an input file is missing or cannot be read as an image",
    4: "an output cannot be written (nothing is left half-written)",
    5: "refused before any work: over the time or memory budget (TEXSYNTH_TIME_BUDGET, "
       "TEXSYNTH_MEMORY_BUDGET)",
    130: "interrupted (Ctrl+C): nothing half-written is left",
}
#: The method when none is named: the README's "any photo, a look first".
DEFAULT_METHOD = "multiscale_mrf"
#: What a job can do with a photo.
OPERATIONS = ("synthesize", "tile", "material")
#: Files taken as photos (a folder's, and the suffixes an output must not take in its source).
PHOTO_SUFFIXES = (".png", ".exr", ".jpg", ".jpeg", ".tif", ".tiff", ".webp")
#: The folder of a batch's keys, inside the output folder.
KEYS = ".texsynth"


class JobError(Exception):
    """One line naming the file, row, column or option, with its exit status ``code``."""

    code = 1


class UsageError(JobError):
    """The command line or a manifest is wrong."""

    code = 2


class InputError(JobError):
    """An input is missing or cannot be read as an image."""

    code = 3


class OutputError(JobError):
    """An output cannot be written."""

    code = 4


class RefusedError(JobError):
    """Over the time or memory budget."""

    code = 5


@dataclass(frozen=True)
class Job:
    """One photo (and its other maps) through one operation into ``outputs``.

    ``outputs`` holds the photo's result, then each map's; ``preview`` the result tiled 2 x 2,
    if asked; ``in_size`` (width, height) resamples the photo and its maps before the work
    (the texel scale: :func:`in_shape`). ``origin`` names where the job came from in errors:
    ``""`` for the command line (errors name its options), ``"lib.csv:3"`` for a manifest row,
    the photo for a folder. ``forecast``: the predicted (seconds, peak bytes) that
    :func:`preflight` found, once it has run (``texsynth.batch.plan`` keeps it here).
    """

    photo: str
    outputs: tuple[str, ...]
    maps: tuple[str, ...] = ()
    operation: str = "synthesize"
    method: str = DEFAULT_METHOD
    width: int = 1024
    height: int = 1024
    seed: int = 0
    band: int | None = None
    params: tuple[tuple[str, object], ...] = ()
    bits: int = 8
    data: bool = False
    preview: str | None = None
    in_size: tuple[int, int] | None = None  # the photo and maps resampled to (W, H) first
    origin: str = ""
    forecast: tuple[float, float] | None = field(default=None, compare=False)

    def recipe(self) -> dict:
        """The parameters that decide the outputs' bits (the key's second half)."""
        fields = dict(operation=self.operation, seed=self.seed, bits=self.bits, data=self.data,
                      suffixes=[Path(o).suffix.lower() for o in self.outputs],
                      in_size=self.in_size)
        if self.operation in ("synthesize", "material"):
            fields.update(method=self.method, width=self.width, height=self.height,
                          params=dict(self.params))
        else:
            fields.update(band=self.band)
        return fields

    def at(self, option: str) -> str:
        """How an error names a value: ``--maps`` on the command line, ``lib.csv:3: maps``."""
        return f"{self.origin}: {option.replace('-', '_')}" if self.origin else f"--{option}"

    def all_outputs(self) -> tuple[str, ...]:
        """Every file the job writes: ``outputs``, then the preview."""
        return (*self.outputs, *([self.preview] if self.preview else []))


def parse_size(text: str) -> tuple[int, int]:
    """``N`` (square) or ``WxH`` as (width, height); ``ValueError`` saying what a size is.

    Examples
    --------
    >>> parse_size("2048"), parse_size("2048x1024")
    ((2048, 2048), (2048, 1024))
    """
    parts = str(text).strip().lower().split("x")
    try:
        values = [int(p) for p in parts]
    except ValueError:
        values = []
    if len(values) not in (1, 2) or min(values) < 1:
        raise ValueError(f"'{text}' is not a size: give N or WIDTHxHEIGHT, e.g. 2048 or "
                         "2048x1024")
    return values[0], values[-1]


def parse_in_size(text: str) -> tuple[int, int]:
    """``--in-size``: ``N`` as (N, 0), the longer side N with the aspect kept (:func:`in_shape`),
    or ``WxH`` as (W, H).

    Examples
    --------
    >>> parse_in_size("1024"), parse_in_size("512x256")
    ((1024, 0), (512, 256))
    """
    width, height = parse_size(text)
    return (width, 0) if "x" not in str(text).lower() else (width, height)


# --- 1. the plan ----------------------------------------------------------------------------

def _identity(path: str) -> tuple:
    """What makes two paths one file: the resolved path (case folded where the system
    folds it), and the inode of a file that exists (hard links)."""
    p = Path(path)
    resolved = os.path.normcase(str(p.resolve()))
    try:
        st = p.stat()
    except OSError:
        return (resolved,)
    return (resolved, (st.st_dev, st.st_ino))


def check_plan(jobs: list[Job], source_folder=None) -> None:
    """Refuse, before any file is opened, a plan that would lose a file.

    Raises :class:`UsageError` when an output's suffix is not a format texsynth writes, an
    output is an input of any job, two outputs are one file, or (``source_folder``: the
    folder whose photos are the inputs) an output would be read as a photo of that folder on
    the next run.

    Examples
    --------
    >>> job = Job(photo="wall.png", outputs=("wall.png",))
    >>> check_plan([job])
    Traceback (most recent call last):
    ...
    texsynth.jobs.UsageError: -o wall.png: would overwrite the input wall.png
    """
    inputs: dict = {}
    for job in jobs:
        for path in (job.photo, *job.maps):
            for part in _identity(path):
                inputs[part] = path
    written: dict = {}
    again = None if source_folder is None else _identity(str(source_folder))[0]
    for job in jobs:
        sources = ("-o", *(f"--maps {m} ->" for m in job.maps), "--preview ->")
        for source, out in zip(sources, job.all_outputs(), strict=False):
            name = f"{job.origin}: {out}" if job.origin else f"{source} {out}"
            try:
                output_format(out)
            except ValueError as error:
                raise UsageError(f"{job.origin}: {error}" if job.origin else f"-o {error}"
                                 ) from None
            parts = _identity(out)
            for part in parts:
                if part in inputs:
                    raise UsageError(f"{name}: would overwrite the input {inputs[part]}")
                if part in written:
                    raise UsageError(f"{name}: the same file as another output, "
                                     f"{written[part]}; give the outputs different names")
            if (again is not None and Path(out).suffix.lower() in PHOTO_SUFFIXES
                    and _identity(str(Path(out).parent))[0] == again):
                raise UsageError(f"-o {Path(out).parent}: the outputs would be read as photos "
                                 "of the same folder on the next run; choose another folder")
            for part in parts:
                written[part] = out


# --- 2. before any work ---------------------------------------------------------------------

def read_input(path, *, header: bool = False):
    """An input image as float32 (H, W, C), upright, or :class:`InputError` naming the file.

    ``header``: only its shape (H, W, C), from the file's headers (``io.image_size``).
    """
    try:
        if header:
            width, height, channels = image_size(path)
            return (height, width, channels)
        return read_photo(path)
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except ImageReadError as error:
        raise InputError(str(error)) from None


def default_bits(path) -> int:
    """The bit depth an output takes from its photo (``io.png_bits``); 8 for a photo that
    cannot be read, which :func:`preflight` then names."""
    try:
        return png_bits(path)
    except (OSError, ValueError):
        return 8


def in_shape(shape, in_size: tuple[int, int] | None) -> tuple[int, int, int]:
    """The shape (H, W, C) a photo of ``shape`` is worked at: ``in_size`` (W, H), where a
    height of 0 keeps the photo's aspect ratio (``--in-size N``: the longer side N).

    Examples
    --------
    >>> in_shape((3000, 4000, 3), (1024, 0)), in_shape((3000, 4000, 3), (512, 256))
    ((768, 1024, 3), (256, 512, 3))
    """
    if in_size is None:
        return tuple(shape)
    h, w, c = shape
    width, height = in_size
    if height == 0:
        scale = width / max(h, w)
        width, height = max(1, round(w * scale)), max(1, round(h * scale))
    return (height, width, c)


def preflight(jobs: list[Job]) -> list[tuple[float, float]]:
    """Check every job as far as it can be without the work, then make the output folders;
    each job's predicted (seconds, peak bytes) on this machine (``budget.forecast``,
    ``tileable.predict``).

    Raises :class:`InputError` for an input that is missing, a folder or not a readable image,
    or a map of another size than its photo; :class:`UsageError` for a bad size, seed, band or
    parameter; :class:`RefusedError` over a budget; :class:`OutputError` when an output folder
    cannot be made or written (checked by making and removing a temporary file in it).
    """
    shapes: dict[str, tuple] = {}
    forecasts = []

    def shape(job, path):
        if path not in shapes:
            try:
                shapes[path] = read_input(path, header=True)
            except InputError as error:
                raise InputError(f"{job.origin}: {error}" if job.origin else str(error)) from None
        return shapes[path]

    for job in jobs:
        photo = shape(job, job.photo)
        try:  # the photo read as float32, before any method's model (a header may say 10^10)
            validation.check_memory(4.0 * np.prod(photo), f"{_named(job)}: reading the "
                                    f"{photo[1]} x {photo[0]} photo", "give a smaller photo")
        except validation.BudgetError as error:
            raise RefusedError(str(error)) from None
        for path in job.maps:
            if shape(job, path)[:2] != photo[:2]:
                raise InputError(f"{job.origin + ': ' if job.origin else ''}{path}: "
                                 f"{shape(job, path)[1]} x {shape(job, path)[0]}, not the "
                                 f"photo's {photo[1]} x {photo[0]}")
        forecasts.append(_check_run(job, in_shape(photo, job.in_size),
                                    _pixels(job) if _reads_joints(job) else None))
    longest: dict[Path, str] = {}
    for out in (Path(out) for job in jobs for out in job.all_outputs()):
        if len(out.name.encode()) > len(longest.get(out.parent, "").encode()):
            longest[out.parent] = out.name
    for folder, name in longest.items():
        check_folder(folder, name)
    for out in (out for job in jobs for out in job.all_outputs()):
        if Path(out).is_dir():  # os.replace onto it would fail after the work
            raise OutputError(f"{out}: a folder of that name is there; choose another output")
    return forecasts


def _reads_joints(job: Job) -> bool:
    """Whether the job's method measures the photo's joints (``joint_width`` 0, its default),
    which its predictions need the photo's pixels to count."""
    if job.operation not in ("synthesize", "material") or (
            job.operation == "material" and dict(job.params).get("size") is None):
        return False  # a material without a size is made tileable: no joints read
    try:
        method = get_method(job.method or material.METHOD)
    except ValueError:
        return False  # named by _check_run
    names = {p.name for p in method.params}
    given = dict(job.params)
    return "joint_width" in names and not given.get("joint_width") \
        and given.get("feature_weight", 1.0) != 0


def _pixels(job: Job):
    """The job's photo read for its prediction (once more than the run reads it: 0.1-0.4 s for
    a 12 MP JPEG); :class:`InputError` naming the row and file when it cannot be read."""
    try:
        return read_input(job.photo)[:, :, :3]
    except InputError as error:  # damage past the headers: refused here, before any work
        text = str(error)
        raise InputError(text if not job.origin or text.startswith(job.origin)
                         else f"{job.origin}: {text}") from None


def _check_run(job: Job, shape, pixels=None) -> tuple[float, float]:
    """The method's own checks (``api.check``, ``tileable.check``) on the photo's shape, and
    the run's predicted (seconds, peak bytes); ``pixels``, the photo, lets the prediction
    count its joints (``budget.forecast``'s ``exemplar``)."""
    if job.operation not in OPERATIONS:
        raise UsageError(f"{job.at('operation')}: must be one of {', '.join(OPERATIONS)}, got "
                         f"{job.operation!r}")
    if job.in_size is not None and max(shape[:2]) > validation.MAX_SIDE:
        raise UsageError(f"{job.at('in-size')}: the photo would be {shape[1]} x {shape[0]}; "
                         f"at most {validation.MAX_SIDE} pixels a side")
    try:
        if job.operation == "material":
            return _check_material(job, shape, pixels)
        if job.operation == "tile":
            band, _ = tileable.check(shape, band=job.band, seed=job.seed)
            return tileable.predict(shape, band)
        method = get_method(job.method)
        if job.maps and not method.positions:
            copying = ", ".join(m.name for m in methods() if m.positions)
            raise UsageError(f"{job.at('maps')}: method {job.method} does not copy photo "
                             f"pixels, so other maps cannot follow it; use one of {copying}")
        width, height, _, params = api.check(shape, job.width, job.height, method=job.method,
                                             seed=job.seed, **dict(job.params))
        return budget.forecast(job.method, shape, width, height, params, exemplar=pixels)
    except validation.BudgetError as error:
        raise RefusedError(f"{_named(job)}: {error}") from None
    except ValueError as error:
        raise UsageError(f"{_named(job)}: {error}") from None


def _named(job: Job) -> str:
    """The job's origin and photo, once each (a folder's job has its photo as origin)."""
    return ": ".join(dict.fromkeys(filter(None, (job.origin, job.photo))))


#: The folders :func:`check_folder` made, parents first: :func:`remove_made_folders` takes
#: them away again when the work fails.
MADE_FOLDERS: list[Path] = []


def remove_made_folders() -> None:
    """Remove the folders :func:`check_folder` made that are still empty, deepest first (a
    failed or interrupted run leaves the disk as it found it)."""
    while MADE_FOLDERS:
        try:
            MADE_FOLDERS.pop().rmdir()
        except OSError:
            pass                                          # something was written there


def check_folder(folder: Path, name: str = "probe") -> None:
    """Make ``folder`` (and its parents; those made in :data:`MADE_FOLDERS`) and write and
    remove a file in it, named as :func:`write_outputs` names its temporary files, and check
    that ``name`` (the folder's longest output) fits the folder's limit on names;
    :class:`OutputError` naming the folder or file: before the work, not after it."""
    try:
        MADE_FOLDERS.extend(reversed([f for f in (folder, *folder.parents) if not f.exists()]))
        folder.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=temp_prefix(Path(name)), dir=folder)
        os.close(fd)
        os.unlink(probe)
        longest = os.pathconf(folder, "PC_NAME_MAX")
    except OSError as error:
        raise OutputError(f"{folder}: cannot write there ({error.strerror or error})") from None
    if len(name.encode()) > longest:
        raise OutputError(f"{folder / name}: the name is {len(name.encode())} bytes long, over "
                          f"the {longest} this folder allows; choose a shorter one")


# --- 3. the work ----------------------------------------------------------------------------

def _finite(image: np.ndarray, path: str) -> None:
    """A result with NaN or infinities from finite inputs is texsynth's fault: never written."""
    if image.size and not (np.isfinite(image.min()) and np.isfinite(image.max())):
        raise JobError(f"{path}: the result holds NaN or infinite values; nothing was written "
                       "(please report this photo)")


def execute(job: Job, progress: Callable[[float, str], object] | None = None) -> list[str]:
    """Do ``job`` and write its outputs (overwriting any file of the same name); the paths.

    Inputs are read (upright, finite: ``io.read_photo``) and resampled to ``in_size``, the
    work runs with ``progress``, every result is checked finite, and the outputs are written
    to temporary files in their folders and renamed over their names only when all are
    complete.
    """
    if job.operation == "material":
        return execute_material(job, progress)[0]
    photo = read_input(job.photo)
    maps = [read_input(path) for path in job.maps]
    if job.in_size is not None:
        h, w, _ = in_shape(photo.shape, job.in_size)
        photo, maps = resample(photo, w, h), [resample(image, w, h) for image in maps]
    if job.operation == "tile":
        result, positions = tileable.make_tileable_positions(photo, band=job.band,
                                                             seed=job.seed, progress=progress)
        moved = [tileable.follow(positions, image, band=job.band) for image in maps]
    elif maps:
        result, positions = api.synthesize_positions(photo, job.width, job.height,
                                                     method=job.method, seed=job.seed,
                                                     progress=progress, **dict(job.params))
        moved = [apply_positions(positions, image) for image in maps]
    else:
        result = api.synthesize(photo, job.width, job.height, method=job.method, seed=job.seed,
                                progress=progress, **dict(job.params))
        moved = []
    if not job.data:
        result = encode(result, is_linear(job.photo), is_linear(job.outputs[0]))
    images = [result, *moved]
    if job.preview:
        preview = tile_preview(result, 2, 2)
        images.append(preview if job.data else encode(preview, is_linear(job.outputs[0]),
                                                      is_linear(job.preview)))
    for path, image in zip(job.all_outputs(), images, strict=True):
        _finite(image, path)
    write_outputs(list(zip(job.all_outputs(), images, strict=True)), job.bits)
    return list(job.all_outputs())


def write_outputs(files: list[tuple[str, np.ndarray]], bits: int) -> None:
    """Every ``(path, image)`` written at once (``io.write_images``: temporary files beside
    them, then renamed; a failure leaves the old files as they were). :class:`OutputError`
    naming the file."""
    try:
        write_images(files, bits)
    except ImageWriteError as error:
        raise OutputError(str(error)) from None
    except OSError as error:
        where = error.filename2 or error.filename  # os.replace's: the output's own name
        raise OutputError(f"{where}: cannot write ({error.strerror or error})") from None


# --- the material operation (issue 43): texsynth.material's pipeline over one photo ---------

def material_job(photo: str, folder, *, mask: str | None = None, size=None, corners=None,
                 skip=(), method: str = DEFAULT_METHOD, seed: int = 0, bits: int = 8,
                 fmt: str = "png", stem: str | None = None, in_size=None,
                 origin: str = "") -> Job:
    """The job that makes ``photo`` (and its ``mask``) into the files of a material in
    ``folder`` (``texsynth.material.pipeline.material_files``: ``<stem>_Color`` and, unless
    the maps are skipped, the four maps), the ``skip``-ped steps left out; ``size`` (width,
    height) synthesizes the colour, None makes the photo itself tile.

    Examples
    --------
    >>> [Path(o).name for o in material_job("floor.jpg", "out").outputs][:2]
    ['floor_Color.png', 'floor_NormalGL.png']
    """
    steps = tuple(s for s in material.STEPS if s not in set(skip))
    suffixes = material.SUFFIXES if "maps" in steps else material.SUFFIXES[:1]
    stem = stem or Path(photo).stem
    params = (("corners", None if corners is None else tuple(map(float, corners))),
              ("format", fmt), ("size", None if size is None else tuple(size)),
              ("steps", steps))
    return Job(photo=str(photo), maps=() if mask is None else (str(mask),),
               outputs=tuple(str(Path(folder) / f"{stem}_{s}.{fmt}") for s in suffixes),
               operation="material", method=method, seed=seed, params=params, bits=bits,
               in_size=in_size, origin=origin)


def _check_material(job: Job, shape, pixels=None) -> tuple[float, float]:
    """``material.check`` on the photo's shape: the material's predicted (seconds, bytes)."""
    p = dict(job.params)
    if p["format"] not in ("png", "exr"):
        raise UsageError(f"{job.at('format')}: a material is written as png or exr, got "
                         f"{p['format']!r}")
    if p["corners"] is not None and len(p["corners"]) != 8:
        raise UsageError(f"{job.at('corners')}: 8 numbers x1,y1,...,x4,y4 (pixels, in order "
                         f"around the rectangle), got {len(p['corners'])}")
    return material.check(shape, size=p["size"], steps=p["steps"], method=job.method,
                          seed=job.seed, masked=bool(job.maps), photo=pixels)


def execute_material(job: Job, progress=None) -> tuple[list[str], tuple[str, ...]]:
    """:func:`execute` of a material job, and the pipeline's line per step (what each did).

    The photo (and mask) read, the EXIF focal length and the corners scaled with ``in_size``,
    the pipeline run, every map checked finite and the set written as :func:`write_outputs`
    does (all or nothing).
    """
    photo = read_input(job.photo)
    mask = read_input(job.maps[0]) if job.maps else None
    if mask is not None:
        check_mask(mask[:, :, 0] >= 0.5, photo.shape)  # before the work: nothing or all masked
    focal = focal_px_from_file(job.photo)
    p = dict(job.params)
    corners = p["corners"]
    if job.in_size is not None:
        h, w, _ = in_shape(photo.shape, job.in_size)
        scale = w / photo.shape[1]
        focal = None if focal is None else focal * scale
        corners = None if corners is None else tuple(v * scale for v in corners)
        photo = resample(photo, w, h)
        mask = None if mask is None else resample(mask, w, h)
    made = material.photo_to_material(
        photo, size=p["size"], mask=None if mask is None else mask[:, :, 0] >= 0.5,
        corners=None if corners is None else np.reshape(corners, (4, 2)), focal_px=focal,
        steps=p["steps"], method=job.method, seed=job.seed, linear=is_linear(job.photo),
        progress=progress)
    first = Path(job.outputs[0])
    files = material.material_files(made, first.parent, first.stem[:-len("_Color")],
                                    fmt=p["format"], from_linear=is_linear(job.photo))
    for path, image in files:
        _finite(image, str(path))
    write_outputs([(str(path), image) for path, image in files], job.bits)
    return [str(path) for path, _ in files], made.steps


# --- 4. keys: resume ------------------------------------------------------------------------

@cache
def code_digest() -> str:
    """SHA-256 of texsynth's own source files: new code, new keys (a checkout has no version
    number that changes with it)."""
    root = Path(__file__).parent
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        h.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes())
    return h.hexdigest()


def version() -> str:
    """The installed texsynth's version (``checkout`` when not installed by pip)."""
    try:
        return metadata.version("texsynth")
    except metadata.PackageNotFoundError:
        return "checkout"


def _file_digest(path) -> str:
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def key(job: Job) -> str:
    """SHA-256 of the inputs' bytes, the job's recipe, and texsynth's code."""
    h = hashlib.sha256(json.dumps([code_digest(), job.recipe()], sort_keys=True).encode())
    for path in (job.photo, *job.maps):
        h.update(_file_digest(path).encode())
    return h.hexdigest()


def _key_path(output: str) -> Path:
    out = Path(output)
    return out.parent / KEYS / (out.name + ".key")


def is_done(job: Job, job_key: str) -> bool:
    """Every output is there with its key and the very bytes that were written with it."""
    for out in job.outputs:
        try:
            record = json.loads(_key_path(out).read_text())
            if record.get("key") != job_key or record.get("sha256") != _file_digest(out):
                return False
        except (OSError, ValueError, AttributeError):
            return False
    return True


def _write_key(output: str, job_key: str) -> None:
    path = _key_path(output)
    path.parent.mkdir(exist_ok=True)
    temp = path.with_name(f"{TEMP_PREFIX}{path.name}-{os.getpid()}")
    temp.write_text(json.dumps({"key": job_key, "sha256": _file_digest(output)}))
    os.replace(temp, path)


def run_job(job: Job, job_key: str | None = None) -> str:
    """A batch's task: ``"skipped"`` when :func:`is_done`, else :func:`execute` and the keys,
    ``"done"``. ``job_key``: the job's :func:`key`, when the caller has it (the batch hashed
    the inputs to find what is done: not twice). Errors propagate as :class:`JobError` (Dask
    hands them back to the batch).

    Examples
    --------
    >>> import tempfile
    >>> from texsynth.io import write_image
    >>> folder = Path(tempfile.mkdtemp())
    >>> write_image(folder / "sand.png", np.random.default_rng(0).random((32, 32, 3)))
    >>> job = Job(photo=str(folder / "sand.png"), outputs=(str(folder / "out.png"),),
    ...           method="heeger_bergen", width=24, height=24)
    >>> ((seconds, peak),) = preflight([job])  # the predicted time and memory
    >>> run_job(job), run_job(job)
    ('done', 'skipped')
    """
    job_key = key(job) if job_key is None else job_key
    if is_done(job, job_key):
        return "skipped"
    execute(job)
    for out in job.outputs:
        _write_key(out, job_key)
    return "done"
