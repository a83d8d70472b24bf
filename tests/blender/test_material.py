"""bpy.ops.texsynth.synthesize_material: every map of a material, consistent, in a copy."""

import bpy
import numpy as np
import pytest
from scenes import fingerprint, generated_image, material_with, noise, pixels_of

FAST = {"method": "MULTISCALE_MRF", "width": 40, "height": 32}


def _follower(tree, image, name, socket):
    node = tree.nodes.new("ShaderNodeTexImage")
    node.name = name
    node.image = image
    node.select = True
    shader = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    tree.links.new(node.outputs["Color"], shader.inputs[socket])
    return node


def _material(colour):
    """Colour (sRGB bytes), roughness = a pixelwise function of it (Non-Color floats), normal
    (Non-Color bytes, 3 channels)."""
    tree = material_with(generated_image(colour, name="colour"))
    rough = (0.2 + 0.6 * colour[:, :, :1] ** 2).astype(np.float32)
    _follower(tree, generated_image(rough, name="rough", float_buffer=True,
                                    colorspace="Non-Color"), "rough node", "Roughness")
    normal = np.concatenate([colour[:, :, 1:], np.ones_like(colour[:, :, :1])], axis=2)
    _follower(tree, generated_image(normal, name="normal", colorspace="Non-Color"),
              "normal node", "Normal")
    tree.nodes["source node"].select = True
    return tree


def _run(mode):
    colour = noise(24, 32, seed=1)
    tree = _material(colour)
    original = bpy.context.active_object.active_material
    before = fingerprint()["materials"][original.name]
    images_before = set(bpy.data.images)
    assert bpy.ops.texsynth.synthesize_material(mode=mode, levels=2, **FAST) == {"FINISHED"}
    made = {i.name: i for i in set(bpy.data.images) - images_before}
    copy = bpy.context.active_object.active_material
    assert copy != original
    assert fingerprint()["materials"][original.name] == before  # the original is untouched
    assert tree.nodes["rough node"].image.name == "rough"
    return copy, made


@pytest.mark.parametrize("mode", ["GUIDED", "COLUMN"])
def test_material_copy_gets_consistent_tileable_maps(addon, mode):
    copy, made = _run(mode)
    names = {"colour_multiscale_mrf_0", "rough_multiscale_mrf_0", "normal_multiscale_mrf_0"}
    assert set(made) == names
    nodes = copy.node_tree.nodes
    assert nodes["source node"].image == made["colour_multiscale_mrf_0"]
    assert nodes["rough node"].image == made["rough_multiscale_mrf_0"]
    assert nodes["normal node"].image == made["normal_multiscale_mrf_0"]
    assert nodes["rough node"].outputs["Color"].links[0].to_socket.name == "Roughness"
    assert made["colour_multiscale_mrf_0"].colorspace_settings.name == "sRGB"
    assert made["rough_multiscale_mrf_0"].colorspace_settings.name == "Non-Color"
    assert made["normal_multiscale_mrf_0"].colorspace_settings.name == "Non-Color"
    for image in made.values():
        assert tuple(image.size) == (40, 32)
    colour = pixels_of(made["colour_multiscale_mrf_0"])[:, :, :3]
    rough = pixels_of(made["rough_multiscale_mrf_0"])[:, :, 0]
    normal = pixels_of(made["normal_multiscale_mrf_0"])[:, :, :2]
    relation = np.abs(rough - (0.2 + 0.6 * colour[:, :, 0] ** 2)).mean() / rough.mean()
    normal_error = np.abs(normal - colour[:, :, 1:]).mean()
    if mode == "COLUMN":
        assert relation < 0.01 and normal_error < 1.5 / 255  # colour stored as bytes
    else:
        assert relation < 0.1 and normal_error < 0.05


def test_in_column_mode_every_map_shows_the_pixel_the_active_one_copied(addon):
    colour = noise(24, 32, seed=1)
    tree = material_with(generated_image(colour, name="colour"))
    # A roughness map whose every pixel is unique: where each output pixel came from is
    # readable from its value.
    ids = (np.arange(24 * 32, dtype=np.float32).reshape(24, 32, 1) + 1) / (24 * 32 + 1)
    _follower(tree, generated_image(ids, name="rough", float_buffer=True,
                                    colorspace="Non-Color"), "rough node", "Roughness")
    tree.nodes["source node"].select = True
    images_before = set(bpy.data.images)

    assert bpy.ops.texsynth.synthesize_material(mode="COLUMN", **FAST) == {"FINISHED"}

    made = {i.name: i for i in set(bpy.data.images) - images_before}
    assert set(made) == {"colour_multiscale_mrf_0", "rough_multiscale_mrf_0"}
    moved = pixels_of(made["rough_multiscale_mrf_0"])[:, :, 0] * (24 * 32 + 1) - 1
    index = np.rint(moved).astype(int)
    assert tuple(made["rough_multiscale_mrf_0"].size) == (40, 32)
    assert len(np.unique(index)) > 20
    expected = colour.reshape(-1, 3)[index]
    got = pixels_of(made["colour_multiscale_mrf_0"])[:, :, :3]
    assert np.abs(got - expected).max() < 1.5 / 255  # the colour result is stored as bytes
    nodes = bpy.context.active_object.active_material.node_tree.nodes
    assert nodes["rough node"].image == made["rough_multiscale_mrf_0"]
    assert nodes["rough node"].outputs["Color"].links[0].to_socket.name == "Roughness"


def test_without_an_active_image_node_the_operator_is_greyed_out_and_says_why():
    op = bpy.ops.texsynth.synthesize_material
    assert not op.poll()
    with pytest.raises(RuntimeError, match=r"poll\(\) No active object: select the object"):
        op(**FAST)
    tree = _material(noise(24, 32))
    tree.nodes.active = tree.nodes["Principled BSDF"]
    before = fingerprint()
    assert not op.poll()
    with pytest.raises(RuntimeError, match="is a Principled BSDF node, not an Image Texture"):
        op(**FAST)
    assert fingerprint() == before
    tree.nodes.active = tree.nodes["source node"]
    assert op.poll()


def test_maps_of_another_size_or_a_method_without_positions_change_nothing(addon):
    tree = _material(noise(24, 32))
    _follower(tree, generated_image(noise(16, 16), name="small"), "small node", "Alpha")
    before = fingerprint()
    with pytest.raises(RuntimeError, match="not 32 x 24"):
        bpy.ops.texsynth.synthesize_material(method="MULTISCALE_MRF", width=16, height=16)
    assert fingerprint() == before
    tree.nodes["small node"].select = False
    with pytest.raises(RuntimeError, match="does not copy pixels"):
        bpy.ops.texsynth.synthesize_material(method="HEEGER_BERGEN", width=16, height=16)
    assert fingerprint() == before
