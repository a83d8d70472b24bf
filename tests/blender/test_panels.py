"""Every TexSynth panel draws, with and without something to work on, and every control it
draws exists (a property of its settings, a registered operator)."""

import math
import types

import bpy
import numpy as np
import pytest
from scenes import generated_image, material_with, noise

#: What each panel must show when the scene has a source, followers and a plane estimate.
EXPECTED = {
    "TEXSYNTH_PT_synthesize": {"method", "width", "height", "seed", "output",
                               "texsynth.synthesize"},
    "TEXSYNTH_PT_material": {"texsynth.synthesize_material"},
    "TEXSYNTH_PT_composite": {"label_image", "output_labels", "texsynth.segment",
                              "texsynth.synthesize_composite"},
    "TEXSYNTH_PT_plane_image": {"method", "slant", "tilt", "confidence",
                                "texsynth.estimate_plane", "texsynth.align_camera",
                                "texsynth.rectify", "texsynth.synthesize"},
    "TEXSYNTH_PT_plane_view3d": {"photo", "method", "slant", "tilt", "confidence",
                                 "texsynth.estimate_plane", "texsynth.align_camera",
                                 "texsynth.rectify", "texsynth.synthesize"},
}


class _Layout:
    """Stands in for a panel's layout: checks every property and operator it is asked to draw
    and records them, and the labels."""

    def __init__(self):
        self.drawn = []
        self.labels = []

    def __getattr__(self, name):  # row, column, box, separator, ...: keep drawing
        return lambda *args, **kwargs: self

    def label(self, text="", **_):
        self.labels.append(text)

    def prop(self, data, name, **_):
        assert name in data.bl_rna.properties, name
        self.drawn.append(name)

    template_ID = prop

    def operator(self, idname, **_):
        category, name = idname.split(".")
        assert name in dir(getattr(bpy.ops, category)), idname
        self.drawn.append(idname)
        return types.SimpleNamespace()


def _draw(name):
    panel = getattr(bpy.types, name)
    layout = _Layout()
    panel.draw(types.SimpleNamespace(layout=layout, in_image_editor=getattr(
        panel, "in_image_editor", False)), bpy.context)
    return layout


def _panels():
    return sorted(n for n in dir(bpy.types) if n.startswith("TEXSYNTH_PT_"))


def test_every_panel_is_tested():
    assert _panels() == sorted(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_every_panel_draws_its_controls(name):
    colour = generated_image(noise(24, 32), name="colour")
    tree = material_with(colour)
    follower = tree.nodes.new("ShaderNodeTexImage")
    follower.image = generated_image(noise(24, 32, seed=2), name="rough")
    follower.select = tree.nodes["source node"].select = True
    settings = bpy.context.scene.texsynth
    settings.method = "MULTISCALE_MRF"
    plane = settings.plane
    plane.has_estimate, plane.image, plane.rectified = True, "colour", "colour"
    plane.slant, plane.tilt = math.radians(40.0), math.radians(90.0)
    layout = _draw(name)
    assert EXPECTED[name] <= set(layout.drawn)
    if name == "TEXSYNTH_PT_material":
        assert {"colour (support)", "rough"} <= set(layout.labels)
        assert layout.drawn.count("texsynth.synthesize_material") == 2  # guided and column


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_every_panel_draws_in_an_empty_file_and_says_what_is_missing(name):
    bpy.context.scene.texsynth.method = "MULTISCALE_MRF"
    layout = _draw(name)
    if name in ("TEXSYNTH_PT_synthesize", "TEXSYNTH_PT_material"):
        assert "No active object: select the object whose material holds the image" in \
            layout.labels
    if name.startswith("TEXSYNTH_PT_plane"):
        assert "texsynth.align_camera" not in layout.drawn  # no estimate yet


def test_the_material_panel_asks_for_a_method_that_copies_pixels():
    material_with(generated_image(np.zeros((16, 16, 3), np.float32)))
    bpy.context.scene.texsynth.method = "HEEGER_BERGEN"
    layout = _draw("TEXSYNTH_PT_material")
    assert layout.labels == ["Choose a method that copies pixels"]
    assert not layout.drawn


def test_the_synthesis_panel_shows_predicted_time_and_memory_before_the_button(addon, monkeypatch):
    material_with(generated_image(noise(24, 32), name="colour"))
    settings = bpy.context.scene.texsynth
    monkeypatch.setattr(addon.texsynth.budget, "_factor", 1.0)  # the reference machine's speed
    settings.method, settings.width, settings.height = "EFROS_LEUNG", 256, 256
    small = [t for t in _draw("TEXSYNTH_PT_synthesize").labels if t.startswith("About ")]
    settings.width = settings.height = 16384
    large = [t for t in _draw("TEXSYNTH_PT_synthesize").labels if t.startswith("About ")]
    assert len(small) == len(large) == 1 and small != large
    assert large[0].split()[2] in ("h,", "days,")  # a job of hours is seen before pressing
