"""Every bad input is reported as an error and leaves the file exactly as it was."""

import os

import bpy
import numpy as np
import pytest
from scenes import fingerprint, generated_image, material_with, noise

from texsynth import io

FAST = {"iterations": 2, "scales": 2, "width": 32, "height": 32}


def _photo():
    return generated_image(noise(32, 32))


def _no_active_object(tmp_path):
    _photo()


def _no_material(tmp_path):
    material_with(_photo())
    bpy.context.active_object.data.materials.clear()


def _no_active_node(tmp_path):
    material_with(_photo()).nodes.active = None


def _active_node_not_an_image_texture(tmp_path):
    tree = material_with(_photo())
    tree.nodes.active = tree.nodes["Principled BSDF"]


def _node_without_image(tmp_path):
    material_with(_photo()).nodes.active.image = None


def _missing_file(tmp_path):
    io.write_png(tmp_path / "gone.png", noise(32, 32))
    image = bpy.data.images.load(str(tmp_path / "gone.png"))
    os.remove(tmp_path / "gone.png")
    material_with(image)


def _one_pixel(tmp_path):
    material_with(generated_image(noise(1, 1)))


def _smaller_than_the_method_needs(tmp_path):
    material_with(generated_image(noise(4, 6)))


def _nan(tmp_path):
    values = noise(32, 32)
    values[3, 5, 1] = np.nan
    material_with(generated_image(values, float_buffer=True))


def _inf(tmp_path):
    values = noise(32, 32)
    values[0, 0, 0] = np.inf
    material_with(generated_image(values, float_buffer=True))


CASES = {
    "no active object": (_no_active_object, {}, "No active object"),
    "no material": (_no_material, {}, "has no active material"),
    "no active node": (_no_active_node, {}, "has no active node"),
    "node of another kind": (_active_node_not_an_image_texture, {},
                             "is a Principled BSDF node, not an Image Texture node"),
    "node without image": (_node_without_image, {}, "has no image"),
    "missing file": (_missing_file, {}, "has no pixel data.*gone.png"),
    "unknown image name": (_no_active_object, {"source_image": "nope"}, "No image named 'nope'"),
    "1 x 1 image": (_one_pixel, {}, "1 x 1 pixels.*at least"),
    "image too small": (_smaller_than_the_method_needs, {}, "6 x 4 pixels.*at least"),
    "NaN": (_nan, {}, "NaN or infinite"),
    "inf": (_inf, {}, "NaN or infinite"),
    "width zero": (lambda t: material_with(_photo()), {"width": 0}, "width must be between"),
    "height negative": (lambda t: material_with(_photo()), {"height": -3},
                        "height must be between"),
    "width too large": (lambda t: material_with(_photo()), {"width": 10**6},
                        "width must be between"),
    "negative seed": (lambda t: material_with(_photo()), {"seed": -1}, "seed"),
    "parameter out of range": (lambda t: material_with(_photo()), {"iterations": 0},
                               "'iterations' must be >= 1"),
    "relative directory, unsaved file": (lambda t: material_with(_photo()),
                                         {"output": "EXR", "output_dir": "//"}, "not saved"),
}


@pytest.mark.parametrize("case", CASES)
def test_bad_input_is_reported_and_changes_nothing(tmp_path, case):
    setup, properties, message = CASES[case]
    setup(tmp_path)
    before = fingerprint()
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.texsynth.synthesize(**{**FAST, **properties})
    assert fingerprint() == before


def test_a_size_over_the_memory_budget_is_refused_before_any_work(monkeypatch):
    material_with(_photo())
    monkeypatch.setenv("TEXSYNTH_MEMORY_BUDGET", str(1 << 20))
    before = fingerprint()
    with pytest.raises(RuntimeError, match="budget"):
        bpy.ops.texsynth.synthesize(**{**FAST, "width": 4096, "height": 4096})
    assert fingerprint() == before


def _nan_follower(tree):
    values = noise(32, 32, seed=2)[:, :, :1].copy()
    values[4, 7, 0] = np.nan
    node = tree.nodes.new("ShaderNodeTexImage")
    node.name = "rough node"
    node.image = generated_image(values, name="rough", float_buffer=True, colorspace="Non-Color")
    node.select = True
    tree.nodes["source node"].select = True


@pytest.mark.parametrize("mode", ["GUIDED", "COLUMN"])
def test_a_nan_map_of_a_material_is_refused_naming_it(mode):
    _nan_follower(material_with(_photo()))
    before = fingerprint()
    with pytest.raises(RuntimeError, match="Image 'rough' of node 'rough node' contains NaN"):
        bpy.ops.texsynth.synthesize_material(mode=mode, method="MULTISCALE_MRF", width=32,
                                             height=32)
    assert fingerprint() == before


@pytest.mark.parametrize("properties, message", [
    ({"interaction_distance": -1}, "'interaction_distance' must be >= 0"),
    ({"levels": 0}, "'levels' must be >= 4"),
    ({"max_offset": 0}, "'max_offset' must be >= 1"),
    ({"width": 0}, "width must be between"),
])
def test_the_composite_operator_checks_its_parameters(properties, message):
    material_with(_photo())
    before = fingerprint()
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.texsynth.synthesize_composite(**{"width": 32, "height": 32, **properties})
    assert fingerprint() == before


def test_a_run_over_the_time_budget_is_refused_naming_the_predicted_time(monkeypatch):
    material_with(_photo())
    monkeypatch.setenv("TEXSYNTH_TIME_BUDGET", "0.001")
    before = fingerprint()
    with pytest.raises(RuntimeError, match="predicted to take about .* TEXSYNTH_TIME_BUDGET"):
        bpy.ops.texsynth.synthesize(**{**FAST, "width": 256, "height": 256})
    assert fingerprint() == before
