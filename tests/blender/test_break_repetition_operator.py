"""texsynth.break_repetition in the bpy module: the node tree it builds, the maps that follow,
what it refuses (and that it then changes nothing), and a small Cycles render of a plane where
the plain texture repeats 8 x 8 times, before and after."""

import bpy
import numpy as np
import pytest
from scenes import fingerprint, generated_image, links, material_with, noise, pixels_of

from benchmarks import norepeat_renders
from texsynth import io
from texsynth.norepeat import gaussianize

GRID, BLEND = "TexSynth Triangle Grid", "TexSynth Variance-Preserving Blend"


def _groups(tree):
    return [n for n in tree.nodes if n.bl_idname == "ShaderNodeGroup"]


def test_the_tree_is_rewired_and_the_users_node_and_image_are_kept():
    tree = material_with(generated_image(noise(32, 32), colorspace="sRGB"))
    source_pixels = np.array(bpy.data.images["source"].pixels)
    assert bpy.ops.texsynth.break_repetition(seed=3) == {"FINISHED"}
    node = tree.nodes["source node"]
    assert node.image.name == "source"
    assert np.array_equal(np.array(bpy.data.images["source"].pixels), source_pixels)
    (group,) = _groups(tree)
    assert tree.nodes.active == group
    to_shader = {(link.from_node.name, link.from_socket.name, link.to_socket.name)
                 for link in tree.links if link.to_node.name == "Principled BSDF"}
    assert to_shader == {(group.name, "Color", "Base Color"), (group.name, "Alpha", "Alpha")}
    assert group.inputs["Vector"].links[0].from_node.bl_idname == "ShaderNodeTexCoord"
    assert group.inputs["Seed"].links[0].from_node.outputs[0].default_value == 3.0
    inner = {n.node_tree.name for n in _groups(group.node_tree)}
    assert inner == {GRID, BLEND}
    images = {n.image for n in group.node_tree.nodes if n.bl_idname == "ShaderNodeTexImage"}
    assert {i.name for i in images} == {"source_tnb_gaussian"}
    for image in images:
        assert image.packed_file is not None and image.is_float
        assert image.colorspace_settings.name == "Non-Color"


@pytest.mark.parametrize("channels", [3, 1])
def test_the_table_curves_give_the_exact_tables_colours(channels):
    """The RGB Curves node standing for the inverse table (texsynth.norepeat.Gaussianized):
    at any centred Gaussian value, within a 16-bit step of the 4096-entry table, every
    channel (a grey map's curve in all three)."""
    image = generated_image(noise(32, 32, channels=channels), colorspace="Non-Color")
    values = pixels_of(image)[:, :, :channels]  # as the operator reads them: bytes
    tree = material_with(image)
    assert bpy.ops.texsynth.break_repetition() == {"FINISHED"}
    (group,) = _groups(tree)
    (curves,) = [n for n in group.node_tree.nodes if n.bl_idname == "ShaderNodeRGBCurve"]
    mapping = curves.mapping
    mapping.initialize()
    g = gaussianize(values)
    x = np.linspace(0.0, 1.0, 301, dtype=np.float32)
    exact = g.look_up(np.repeat(x[:, None], channels, axis=1))
    exact = np.repeat(exact, 3, axis=1) if channels == 1 else exact
    got = np.array([[mapping.evaluate(mapping.curves[k], mapping.evaluate(
        mapping.curves[3], float(v) - 0.5)) for k in range(3)] for v in x])
    assert np.abs(got - exact).max() < 2 / 255
    gaussian = next(n.image for n in group.node_tree.nodes if n.bl_idname == "ShaderNodeTexImage")
    stored = np.empty(len(gaussian.pixels), np.float32)
    gaussian.pixels.foreach_get(stored)
    stored = stored.reshape(32, 32, 4)[::-1, :, :3]
    assert np.allclose(stored, g.gaussian[:, :, :1] - 0.5 if channels == 1 else g.gaussian - 0.5)


def test_an_unlinked_vector_becomes_the_uv_map_the_image_node_used():
    tree = material_with(generated_image(noise(32, 32)))
    tree.links.remove(tree.nodes["source node"].inputs["Vector"].links[0])
    assert bpy.ops.texsynth.break_repetition() == {"FINISHED"}
    (group,) = _groups(tree)
    assert group.inputs["Vector"].links[0].from_node.bl_idname == "ShaderNodeUVMap"


def test_the_shared_groups_are_reused_by_a_second_material():
    material_with(generated_image(noise(32, 32)))
    bpy.ops.texsynth.break_repetition()
    material_with(generated_image(noise(32, 32, seed=1), name="other"))
    bpy.ops.texsynth.break_repetition()
    names = sorted(g.name for g in bpy.data.node_groups)
    assert names == sorted([GRID, BLEND, "TexSynth T&B source", "TexSynth T&B other"])


def test_selected_maps_follow_with_the_same_vector_scale_and_seed():
    tree = material_with(generated_image(noise(32, 32)))
    rough = tree.nodes.new("ShaderNodeTexImage")
    rough.name = "rough node"
    rough.image = generated_image(noise(64, 64, channels=1, seed=2), name="rough",
                                  colorspace="Non-Color")
    tree.links.new(rough.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Roughness"])
    rough.select = tree.nodes["source node"].select = True
    assert bpy.ops.texsynth.break_repetition() == {"FINISHED"}
    groups = _groups(tree)
    assert len(groups) == 2
    for socket in ("Vector", "Scale", "Seed"):
        assert len({g.inputs[socket].links[0].from_socket.as_pointer() for g in groups}) == 1
    roughness = tree.nodes["Principled BSDF"].inputs["Roughness"].links[0].from_node
    assert roughness in groups and roughness.node_tree.name == "TexSynth T&B rough"


def _write(tmp_path, values, bits):
    path = tmp_path / f"photo{bits}.png"
    io.write_png(path, values, bits=bits)
    return bpy.data.images.load(str(path))


@pytest.mark.parametrize("case", ["packed", "float", "grey", "16-bit"])
def test_unusual_images_work(tmp_path, case):
    values = noise(32, 32)
    if case == "packed":
        image = _write(tmp_path, values, 8)
        image.pack()
    elif case == "float":
        image = generated_image(values, float_buffer=True)
    elif case == "grey":
        image = generated_image(values[:, :, :1])
    else:
        image = _write(tmp_path, values, 16)
        assert image.is_float
    tree = material_with(image)
    assert bpy.ops.texsynth.break_repetition() == {"FINISHED"}
    assert len(_groups(tree)) == 1


def _not_an_image_node(tmp_path):
    tree = material_with(generated_image(noise(32, 32)))
    tree.nodes.active = tree.nodes["Principled BSDF"]


def _no_image(tmp_path):
    material_with(generated_image(noise(32, 32))).nodes.active.image = None


def _varying_alpha(tmp_path):
    material_with(generated_image(noise(32, 32, channels=4)))


def _other_colour_space(tmp_path):
    material_with(generated_image(noise(32, 32), colorspace="Linear Rec.709"))


def _one_pixel(tmp_path):
    material_with(generated_image(noise(1, 1)))


CASES = {
    "no active object": (lambda t: generated_image(noise(32, 32)), "No active object"),
    "node of another kind": (_not_an_image_node, "not an Image Texture node"),
    "node without image": (_no_image, "has no image"),
    "varying alpha": (_varying_alpha, "varying alpha"),
    "linear bytes": (_other_colour_space, "colour space 'Linear Rec.709'"),
    "1 x 1 image": (_one_pixel, "at least 2 x 2"),
}


@pytest.mark.parametrize("case", CASES)
def test_bad_input_is_reported_and_changes_nothing(tmp_path, case):
    setup, message = CASES[case]
    setup(tmp_path)
    before = fingerprint()
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.texsynth.break_repetition()
    assert fingerprint() == before


def test_a_huge_image_is_refused_before_any_work(monkeypatch):
    material_with(generated_image(noise(256, 256)))
    monkeypatch.setenv("TEXSYNTH_MEMORY_BUDGET", str(1 << 20))
    before = fingerprint()
    with pytest.raises(RuntimeError, match="budget"):
        bpy.ops.texsynth.break_repetition()
    assert fingerprint() == before


def test_a_cycles_render_no_longer_repeats_and_keeps_its_look():
    """8 x 8 tiles of the CC0 sample at 16 pixels a tile, plain and after; the figures the
    issue asks of the benchmark, on a small render."""
    photo = io.read_photo(norepeat_renders.REPO / "samples" / "pool_water.png")[:, :, :3]
    tree = norepeat_renders.scene(photo, 8, 128, 16)
    plain, _ = norepeat_renders.render()
    before = links(tree)
    assert bpy.ops.texsynth.break_repetition() == {"FINISHED"}
    assert links(tree) != before
    after, _ = norepeat_renders.render()
    m = norepeat_renders.measures(plain, after, 16)
    print(m)
    assert m["corr_plain"] > 0.8
    assert abs(m["corr_after"]) < 0.3
    assert m["wasserstein"] < 0.03
    assert 0.85 < m["gradient_ratio"] < 1.15
