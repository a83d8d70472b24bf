"""Composite mode in Blender: segmentation image, label sources, painted layout, bad input."""

import bpy
import numpy as np
import pytest
from scenes import fingerprint, generated_image, material_with, pixels_of

FAST = {"max_cliques": 4, "sweeps": 4}
RED, BLUE = np.array([0.8, 0.25, 0.2]), np.array([0.2, 0.35, 0.85])


def _two_colour_photo(h=40, w=40):
    rng = np.random.default_rng(0)
    truth = np.zeros((h, w), np.int32)
    truth[:, w // 2:] = 1
    img = np.where(truth[:, :, None] == 1, BLUE, RED) + rng.normal(0, 0.04, (h, w, 3))
    return np.clip(img, 0, 1).astype(np.float32), truth


def test_segmentation_is_shown_as_a_new_image_and_becomes_the_label_source():
    photo, truth = _two_colour_photo()
    source = generated_image(photo)
    material_with(source)
    before = pixels_of(source).copy()
    assert bpy.ops.texsynth.segment() == {"FINISHED"}
    made = bpy.data.images["source_labels"]
    assert tuple(made.size) == (40, 40)
    colours = np.unique(pixels_of(made)[:, :, :3].reshape(-1, 3), axis=0)
    assert len(colours) == 2
    assert bpy.context.scene.texsynth.composite.label_image == made
    np.testing.assert_array_equal(pixels_of(source), before)


def test_composite_with_automatic_labels_makes_an_image_a_node_and_a_label_map():
    photo, _ = _two_colour_photo()
    tree = material_with(generated_image(photo))
    result = bpy.ops.texsynth.synthesize_composite(width=32, height=24, **FAST)
    assert result == {"FINISHED"}
    image = tree.nodes.active.image
    assert image.name == "source_composite_0" and tuple(image.size) == (32, 24)
    layout = bpy.data.images["source_composite_0_labels"]
    assert tuple(layout.size) == (32, 24)


def test_a_painted_layout_sets_the_output_size_and_is_followed():
    photo, truth = _two_colour_photo()
    tree = material_with(generated_image(photo))
    paint = np.where(truth[:, :, None] == 1, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    generated_image(paint.astype(np.float32), name="painted labels")
    plan = np.zeros((24, 36, 3), np.float32)
    plan[:, :, 0] = 1.0
    plan[6:18, 10:30] = [0.0, 0.0, 1.0]
    generated_image(plan, name="layout")
    result = bpy.ops.texsynth.synthesize_composite(label_image="painted labels",
                                                   output_labels="layout", **FAST)
    assert result == {"FINISHED"}
    out = pixels_of(tree.nodes.active.image)
    assert out.shape[:2] == (24, 36)
    blue_region = plan[:, :, 2] == 1.0
    assert ((out[:, :, 2] > out[:, :, 0]) == blue_region).mean() > 0.97


def test_a_label_image_of_the_wrong_size_changes_nothing():
    photo, truth = _two_colour_photo()
    material_with(generated_image(photo))
    generated_image(np.zeros((20, 20, 3), np.float32), name="small labels")
    before = fingerprint()
    with pytest.raises(RuntimeError, match="label image is 20 x 20 pixels; it must be 40 x 40"):
        bpy.ops.texsynth.synthesize_composite(label_image="small labels", width=16, height=16,
                                              **FAST)
    assert fingerprint() == before
