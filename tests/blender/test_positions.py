"""bpy.ops.texsynth.synthesize_maps: other maps of the material follow the same positions."""

import bpy
import numpy as np
import pytest
from scenes import fingerprint, generated_image, material_with, noise, pixels_of

FAST = {"method": "MULTISCALE_MRF", "width": 40, "height": 32}


def _follower(tree, image, name):
    node = tree.nodes.new("ShaderNodeTexImage")
    node.name = name
    node.image = image
    shader = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    tree.links.new(node.outputs["Color"], shader.inputs["Roughness"])
    return node


def test_selected_maps_follow_the_synthesis_of_the_active_one(addon):
    colour = noise(24, 32, seed=1)
    tree = material_with(generated_image(colour, name="colour"))
    # A roughness map whose every pixel is unique: where each output pixel came from is
    # readable from its value.
    ids = (np.arange(24 * 32, dtype=np.float32).reshape(24, 32, 1) + 1) / (24 * 32 + 1)
    rough = _follower(tree, generated_image(ids, name="rough", float_buffer=True,
                                            colorspace="Non-Color"), "rough node")
    rough.select = True
    tree.nodes["source node"].select = True
    images_before = set(bpy.data.images)

    assert bpy.ops.texsynth.synthesize_maps(**FAST) == {"FINISHED"}

    made = {i.name: i for i in set(bpy.data.images) - images_before}
    assert set(made) == {"colour_multiscale_mrf_0", "rough_multiscale_mrf_0"}
    assert tree.nodes.active.image == made["colour_multiscale_mrf_0"]
    # The roughness result tells, per pixel, which exemplar pixel was copied; the colour result
    # must show exactly that pixel of the colour map.
    moved = pixels_of(made["rough_multiscale_mrf_0"])[:, :, 0] * (24 * 32 + 1) - 1
    index = np.rint(moved).astype(int)
    assert tuple(made["rough_multiscale_mrf_0"].size) == (40, 32)
    assert len(np.unique(index)) > 20
    expected = colour.reshape(-1, 3)[index]
    got = pixels_of(made["colour_multiscale_mrf_0"])[:, :, :3]
    assert np.abs(got - expected).max() < 1.5 / 255  # the colour result is stored as bytes
    # The follower's new node took over the roughness link.
    new_rough = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeTexImage"
                     and n.image == made["rough_multiscale_mrf_0"])
    assert new_rough.outputs["Color"].links[0].to_socket.name == "Roughness"


def test_maps_of_another_size_or_a_method_without_positions_change_nothing(addon):
    tree = material_with(generated_image(noise(24, 32), name="colour"))
    other = _follower(tree, generated_image(noise(16, 16), name="small"), "small node")
    other.select = True
    before = fingerprint()
    with pytest.raises(RuntimeError, match="not 32 x 24"):
        bpy.ops.texsynth.synthesize_maps(**FAST)
    assert fingerprint() == before
    other.select = False
    before = fingerprint()
    with pytest.raises(RuntimeError, match="does not copy pixels"):
        bpy.ops.texsynth.synthesize_maps(method="HEEGER_BERGEN", width=16, height=16)
    assert fingerprint() == before
