"""bpy.ops.texsynth.make_tileable: the photo made to tile into a new image and node, the user's
image untouched, the other selected maps following the same positions on request."""

import bpy
import numpy as np
import pytest
from scenes import fingerprint, generated_image, material_with, pixels_of

from texsynth.metrics import seam_ratio


def photo(seed=0, h=64, w=80):
    """A crop of smooth noise: a photo-like texture whose opposite edges do not match."""
    from scipy.ndimage import gaussian_filter

    rng = np.random.default_rng(seed)
    big = gaussian_filter(rng.standard_normal((h + 40, w + 40, 3)), (2.5, 2.5, 0), mode="wrap")
    crop = big[17:17 + h, 23:23 + w]
    return ((crop - crop.min()) / np.ptp(crop) * 0.8 + 0.1).astype(np.float32)


def test_the_photo_becomes_a_new_tileable_image_and_node(addon):
    colour = photo()
    tree = material_with(generated_image(colour, name="wall"))
    user_pixels = pixels_of(bpy.data.images["wall"]).copy()
    images_before = set(bpy.data.images)

    assert bpy.ops.texsynth.make_tileable() == {"FINISHED"}

    (made,) = set(bpy.data.images) - images_before
    assert made.name == "wall_tileable_0" and tuple(made.size) == (80, 64)
    assert np.array_equal(pixels_of(bpy.data.images["wall"]), user_pixels)  # untouched
    result = pixels_of(made)[:, :, :3]
    # The wrap, a step of 5.4x the photo's own, is gone, and no softer than the photo: 1.06
    # (1.31 while the cuts kept the pieces' difference of level, before the band's correction;
    # over 4 such photos x 5 seeds 0.73-1.22, then 0.93-1.69).
    assert seam_ratio(user_pixels[:, :, :3]) > 2 and 0.85 < seam_ratio(result) < 1.15
    # Most pixels are the photo's own (8-bit storage: within a byte step).
    kept = (np.abs(result - user_pixels[:, :, :3]) < 1.5 / 255).all(axis=2)
    assert kept.mean() >= 0.5 and kept[16:48, 20:60].all()
    node = tree.nodes.active
    assert node.image == made and node.extension == "REPEAT"
    assert node.outputs["Color"].links[0].to_socket.name == "Base Color"


def test_selected_maps_follow_with_the_same_positions(addon):
    colour = photo(1)
    # Floats as they are (an sRGB colour is corrected in linear light, a data map as it is).
    tree = material_with(generated_image(colour, name="colour", float_buffer=True,
                                         colorspace="Non-Color"))
    # A roughness map that is the colour's red channel: it must come out as the colour's red
    # does (the same pieces and the same correction of the band).
    red = colour[:, :, :1].copy()
    rough = tree.nodes.new("ShaderNodeTexImage")
    rough.name = "rough node"
    rough.image = generated_image(red, name="rough", float_buffer=True, colorspace="Non-Color")
    rough.select = True
    tree.nodes["source node"].select = True
    images_before = set(bpy.data.images)

    assert bpy.ops.texsynth.make_tileable(all_maps=True, seed=2) == {"FINISHED"}

    made = {i.name: i for i in set(bpy.data.images) - images_before}
    assert set(made) == {"colour_tileable_2", "rough_tileable_2"}
    followed = pixels_of(made["rough_tileable_2"])[:, :, 0]
    expected = pixels_of(made["colour_tileable_2"])[:, :, 0]
    # Each channel is corrected by itself; the sweeps end when all of a map's channels are
    # within a quarter of an 8-bit step of the solution.
    assert np.abs(followed - expected).max() < 1 / 255
    assert seam_ratio(red[:, :, 0]) > 2 and 0.85 < seam_ratio(followed) < 1.15
    assert not np.array_equal(followed, red[:, :, 0])  # the band did change


def test_errors_change_nothing(addon):
    tree = material_with(generated_image(photo(), name="wall"))
    before = fingerprint()
    with pytest.raises(RuntimeError, match="more than half"):
        bpy.ops.texsynth.make_tileable(band=60)
    assert fingerprint() == before
    tree.nodes.active = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    before = fingerprint()
    with pytest.raises(RuntimeError, match="not an Image Texture node"):
        bpy.ops.texsynth.make_tileable()
    assert fingerprint() == before


@pytest.mark.parametrize("channels", [1, 3, 4])
def test_a_photo_comes_back_upright_in_its_channels(addon, channels):
    """Grey, colour, and colour with a varying alpha, of an odd height that Blender hands over
    in several blocks of rows: the kept centre is the photo's own, where it was (floats:
    exactly)."""
    h, w = 301, 700
    values = np.concatenate([photo(3, h, w), photo(4, h, w)], axis=2)[:, :, :channels]
    material_with(generated_image(values, name="photo", float_buffer=True,
                                  colorspace="Non-Color"))
    user = pixels_of(bpy.data.images["photo"]).copy()
    before = set(bpy.data.images)

    assert bpy.ops.texsynth.make_tileable(band=40) == {"FINISHED"}

    (made,) = set(bpy.data.images) - before
    result = pixels_of(made)
    centre = (slice(40, h - 40), slice(40, w - 40))
    assert np.array_equal(result[centre], user[centre])
    assert not np.array_equal(result, user)  # the band changed
