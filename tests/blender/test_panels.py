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
                               "texsynth.synthesize", "band", "texsynth.make_tileable"},
    "TEXSYNTH_PT_material": {"texsynth.synthesize_material"},
    "TEXSYNTH_PT_norepeat": {"texsynth.break_repetition"},
    "TEXSYNTH_PT_photo_material": {"texsynth.photo_to_material"},
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
    and records them, and the labels (their icons too), in the order drawn."""

    def __init__(self):
        self.drawn = []
        self.labels = []
        self.icons = []
        self.order = []

    def __getattr__(self, name):  # row, column, box, separator, ...: keep drawing
        return lambda *args, **kwargs: self

    def label(self, text="", icon="NONE", **_):
        self.labels.append(text)
        self.icons.append(icon)
        self.order.append(text)

    def prop(self, data, name, **_):
        assert name in data.bl_rna.properties, name
        self.drawn.append(name)
        self.order.append(name)

    template_ID = prop

    def operator(self, idname, **_):
        category, name = idname.split(".")
        assert name in dir(getattr(bpy.ops, category)), idname
        self.drawn.append(idname)
        self.order.append(idname)
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


def _synthesis_prediction(layout):
    """The label drawn right above the Synthesize button."""
    return layout.order[layout.order.index("texsynth.synthesize") - 1]


def test_the_synthesis_panel_shows_predicted_time_and_memory_before_the_button(addon, monkeypatch):
    material_with(generated_image(noise(24, 32), name="colour"))
    settings = bpy.context.scene.texsynth
    monkeypatch.setattr(addon.texsynth.budget, "machine_factor", lambda: 1.0)  # reference
    settings.method, settings.width, settings.height = "EFROS_LEUNG", 256, 256
    small = _synthesis_prediction(_draw("TEXSYNTH_PT_synthesize"))
    settings.width = settings.height = 16384
    large = _synthesis_prediction(_draw("TEXSYNTH_PT_synthesize"))
    assert small.startswith("About ") and large.startswith("About ") and small != large
    assert large.split()[2] in ("h,", "days,")  # a job of hours is seen before pressing


def test_make_tileable_shows_its_predicted_time_and_memory_for_the_photo_and_band(addon,
                                                                                 monkeypatch):
    """Above the Make Tileable button: the time and memory texsynth.tileable.predict gives for
    the active image's size and the panel's band, flagged when over a budget."""
    material_with(bpy.data.images.new("photo", 4000, 3000))  # 12 MP; its pixels are not read
    settings = bpy.context.scene.texsynth
    settings.band = 200
    layout = _draw("TEXSYNTH_PT_synthesize")
    seconds, need = addon.texsynth.tileable.predict((3000, 4000, 3), 200)
    seconds += addon.operators.output.predict_seconds(12_000_000, 12_000_000, settings.output)
    shown = f"About {addon.texsynth.budget.describe(seconds)}, {need / 2**30:.2g} GiB"
    at = layout.order.index("texsynth.make_tileable")
    assert layout.order[at - 1] == shown and layout.order[at - 2] == "band"
    icons = []
    for time_budget, memory_budget in ((2 * seconds, 2 * need), (seconds / 2, 2 * need),
                                       (2 * seconds, need / 2)):
        monkeypatch.setenv("TEXSYNTH_TIME_BUDGET", str(time_budget))
        monkeypatch.setenv("TEXSYNTH_MEMORY_BUDGET", str(int(memory_budget)))
        layout = _draw("TEXSYNTH_PT_synthesize")
        icons.append(layout.icons[layout.labels.index(shown)])
    assert icons == ["TIME", "ERROR", "ERROR"]
