"""bpy.ops.texsynth.photo_to_material: a new material wired from new images, the user's photo,
node and material kept, nothing made on error, one Ctrl+Z undoes it all."""

import bpy
import numpy as np
import pytest
from scenes import fingerprint, generated_image, material_with, noise, pixels_of

FAST = {"size": 32, "steps": {"DELIGHT", "TILE", "MAPS"}}


def _linked(socket):
    return socket.links[0].from_node


def test_a_new_material_is_wired_from_five_new_images_and_the_users_are_kept():
    tree = material_with(generated_image(noise(48, 64), name="floor", colorspace="sRGB"))
    original = bpy.context.active_object.active_material
    photo = pixels_of(bpy.data.images["floor"]).copy()
    images = set(bpy.data.images)

    assert bpy.ops.texsynth.photo_to_material(**FAST) == {"FINISHED"}

    made = set(bpy.data.images) - images
    assert sorted(i.name for i in made) == sorted(
        f"floor_material_0_{s}" for s in ("Color", "NormalGL", "Displacement", "Roughness",
                                          "AmbientOcclusion"))
    assert all(tuple(i.size) == (32, 32) for i in made)
    assert np.array_equal(pixels_of(bpy.data.images["floor"]), photo)
    assert tree.nodes["source node"].image.name == "floor" and original.use_fake_user
    material = bpy.context.active_object.active_material
    assert material != original
    bsdf = next(n for n in material.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    mix = _linked(bsdf.inputs["Base Color"])
    assert mix.blend_type == "MULTIPLY" and {_linked(s).image.name for s in mix.inputs
                                             if s.is_linked} == {"floor_material_0_Color",
                                                                 "floor_material_0_AmbientOcclusion"}
    assert _linked(bsdf.inputs["Roughness"]).image.name == "floor_material_0_Roughness"
    bump = _linked(bsdf.inputs["Normal"])
    assert _linked(bump.inputs["Height"]).image.name == "floor_material_0_Displacement"
    normal_map = _linked(bump.inputs["Normal"])
    assert normal_map.bl_idname == "ShaderNodeNormalMap"
    assert _linked(normal_map.inputs["Color"]).image.colorspace_settings.name == "Non-Color"


def test_a_mask_of_another_size_refuses_and_nothing_is_made():
    material_with(generated_image(noise(48, 64), name="floor"))
    generated_image(noise(16, 16), name="small")
    before = fingerprint()
    with pytest.raises(RuntimeError, match="Mask 'small' is 16 x 16, not the photo's 64 x 48"):
        bpy.ops.texsynth.photo_to_material(mask="small", **FAST)
    assert fingerprint() == before


def test_one_ctrl_z_undoes_it():
    material_with(generated_image(noise(48, 64), name="floor", colorspace="sRGB"))
    bpy.ops.ed.undo_push(message="before")
    before = fingerprint()
    assert bpy.ops.texsynth.photo_to_material("EXEC_DEFAULT", True, **FAST) == {"FINISHED"}
    assert fingerprint() != before
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert fingerprint() == before
