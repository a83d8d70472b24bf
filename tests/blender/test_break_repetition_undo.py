"""Ctrl+Z after texsynth.break_repetition, in the bpy module: the operator runs as the UI runs
it (one undo step: ``bpy.ops`` with ``undo=True`` pushes the step the UI would), then
``bpy.ops.ed.undo()`` brings back the file as it was (global undo works without a window)."""

import bpy
import pytest
from scenes import fingerprint, generated_image, material_with, noise


@pytest.mark.parametrize("mode", ["TILING_AND_BLENDING", "TILE_SET", "HEX_TILING"])
def test_one_ctrl_z_undoes_break_repetition(mode):
    material_with(generated_image(noise(64, 64), colorspace="sRGB"))
    bpy.ops.ed.undo_push(message="before")
    before = fingerprint()
    groups = set(bpy.data.node_groups)
    assert bpy.ops.texsynth.break_repetition("EXEC_DEFAULT", True, mode=mode) == {"FINISHED"}
    assert fingerprint() != before and set(bpy.data.node_groups) != groups
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert fingerprint() == before
    assert not any(g.name.startswith("TexSynth") for g in bpy.data.node_groups)
    assert bpy.ops.ed.redo() == {"FINISHED"}
    assert fingerprint() != before
