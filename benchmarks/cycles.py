"""The Cycles set-up the benchmark renderers share (bpy imported on first use)."""

from __future__ import annotations


def cpu_scene(samples: int, width: int, height: int, threads: int = 1):
    """A new empty file's scene rendering with Cycles on the CPU, without denoising, at
    ``width`` x ``height`` with a fixed thread count and the Standard view transform."""
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.preferences.addon_enable(module="cycles")
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
    scene.view_settings.view_transform = "Standard"
    return scene
