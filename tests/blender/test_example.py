"""examples/synthesize_file.py, run the way a user runs it (Python with the bpy module)."""

import subprocess
import sys
from pathlib import Path

import bpy

from texsynth import io

REPO = Path(__file__).resolve().parents[2]


def test_the_headless_example_writes_the_exr_the_blend_and_a_tiled_preview(tmp_path):
    run = subprocess.run(
        [sys.executable, str(REPO / "examples" / "synthesize_file.py"),
         str(REPO / "samples" / "pool_water.png"), "--width", "96", "--height", "64",
         "--iterations", "2", "--seed", "3", "--out", str(tmp_path)],
        capture_output=True, text=True, timeout=600,
    )
    assert run.returncode == 0, run.stderr
    stem = tmp_path / "pool_water_heeger_bergen_3"
    exr, blend, preview = (stem.with_suffix(".exr"), stem.with_suffix(".blend"),
                           tmp_path / f"{stem.name}_tiled.png")
    assert run.stdout.split("\n")[-4:] == [f"wrote {exr}", f"wrote {blend}", f"wrote {preview}", ""]
    texture = io.read_exr(exr)
    assert texture.shape == (64, 96, 3)
    assert io.read_png(preview).shape == (128, 192, 3)

    bpy.ops.wm.open_mainfile(filepath=str(blend))
    tree = bpy.data.materials["pool_water"].node_tree
    shader = tree.nodes["Principled BSDF"]
    (link,) = shader.inputs["Base Color"].links
    image = link.from_node.image
    assert image.filepath == "//pool_water_heeger_bergen_3.exr"
    assert tuple(image.size) == (96, 64) and image.has_data
