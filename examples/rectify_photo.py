"""From a photo of a textured plane taken at an angle to a seamless texture, with the core alone.

    python examples/rectify_photo.py PHOTO [--focal-px F] [--width 1024] [--height 1024]
        [--method heeger_bergen] [--seed 0] [--out out]

Estimates the plane's slant and tilt from the texture and its lines (``texsynth.estimate_plane``;
the focal length in pixels of PHOTO when known: ``--focal-px``, else the file's EXIF, else
estimated), prints them, writes the frontal view
``<photo>_rectified.png`` and a ``--width`` x ``--height`` seamless texture synthesized from it,
``<photo>_<method>_<seed>.png`` (``--width 0`` skips the synthesis). Any photo in (PNG,
OpenEXR, TIFF, JPEG, WebP: read upright, by its EXIF orientation); no Blender needed.
"""

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import texsynth  # noqa: E402
from texsynth import io  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("photo", type=Path)
    parser.add_argument("--focal-px", type=float, default=None,
                        help="focal length in pixels of the photo (default: from its EXIF, "
                             "else estimated)")
    parser.add_argument("--width", type=int, default=1024)
    parser.add_argument("--height", type=int, default=1024)
    parser.add_argument("--method", default="heeger_bergen",
                        choices=[m.name for m in texsynth.methods()])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("out"))
    args = parser.parse_args(argv)

    try:
        photo = io.read_photo(args.photo)
    except (FileNotFoundError, io.ImageReadError) as error:  # each names the file
        parser.error(str(error))
    try:
        focal_px = args.focal_px if args.focal_px is not None else \
            texsynth.focal_px_from_file(args.photo)
        plane = texsynth.estimate_plane(photo, focal_px=focal_px)
        frontal = texsynth.rectify(photo, plane)
    except ValueError as error:
        parser.error(f"{args.photo}: {error}")
    either = " (or +180: no perspective to tell)" if plane.tilt_ambiguous_180 else ""
    focal = ("orthographic" if plane.focal_px is None else
             f"focal {plane.focal_px:.0f} px{' (estimated)' if plane.focal_estimated else ''}")
    print(f"slant {plane.slant:.1f} deg, tilt {plane.tilt:.1f} deg{either}, {focal}, "
          f"confidence {plane.confidence:.2f} (normal +- {plane.normal_uncertainty:.1f} deg)")
    args.out.mkdir(parents=True, exist_ok=True)
    stem = args.photo.stem
    written = [(args.out / f"{stem}_rectified.png", frontal)]
    if args.width > 0:
        texture = texsynth.synthesize(frontal, args.width, args.height, method=args.method,
                                      seed=args.seed)
        written.append((args.out / f"{stem}_{args.method}_{args.seed}.png", texture))
    for path, image in written:
        io.write_png(path, image)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
