"""bpy.ops.texsynth.synthesize from the installed zip: the new image and node, colour handling."""

import os
import sys
import time
from pathlib import Path

import bpy
import mathutils
import numpy as np
import pytest
from scenes import generated_image, links, material_with, noise, pixels_of, synthesize

from texsynth import io
from texsynth.blocks import color

FAST = {"iterations": 2, "scales": 2}


def test_the_zip_installs_the_operator_panel_and_settings(addon):
    assert addon.__name__ == "bl_ext.user_default.texsynth"
    site = Path(bpy.utils.user_resource("EXTENSIONS"), ".local", "lib",
                f"python{sys.version_info.major}.{sys.version_info.minor}", "site-packages")
    assert (site / "scipy").is_dir() and any(site.glob("OpenEXR*")), "bundled wheels missing"
    panel = bpy.types.TEXSYNTH_PT_synthesize
    assert (panel.bl_space_type, panel.bl_region_type, panel.bl_category) == (
        "NODE_EDITOR", "UI", "TexSynth")
    props = bpy.ops.texsynth.synthesize.get_rna_type().properties
    methods = addon.texsynth.methods()
    assert [i.identifier for i in props["method"].enum_items] == [m.name.upper() for m in methods]
    for p in addon.texsynth.get_method("heeger_bergen").params:
        assert getattr(bpy.context.scene.texsynth.params.heeger_bergen, p.name) == p.default
    assert {"width", "height", "seed", "output", "output_dir", "source_image"} <= set(props.keys())


def test_every_parameter_of_every_method_is_one_operator_property_by_its_name(addon):
    props = bpy.ops.texsynth.synthesize.get_rna_type().properties
    kinds = {int: "INT", float: "FLOAT", bool: "BOOLEAN", str: "ENUM"}
    for method in addon.texsynth.methods():
        for param in method.params:
            prop = props[param.name]
            assert prop.type == kinds[param.type], (method.name, param.name)
            if param.type is str:
                assert set(param.choices) <= {i.identifier for i in prop.enum_items}
            elif param.type is not bool and param.min is not None:
                assert prop.soft_min <= param.min and prop.soft_max >= param.max
    assert not [name for name in props.keys() if "__" in name]  # nothing namespaced


def test_each_method_keeps_its_own_values_starting_at_its_registry_defaults(addon):
    params = bpy.context.scene.texsynth.params
    for method in addon.texsynth.methods():
        group = getattr(params, method.name)
        for p in method.params:
            assert getattr(group, p.name) == pytest.approx(p.default), (method.name, p.name)
    mrf = addon.texsynth.get_method("multiscale_mrf").param("levels")
    co = addon.texsynth.get_method("cooccurrence").param("levels")
    assert mrf.default != co.default  # one name, two defaults: what this test is about
    params.multiscale_mrf.levels = mrf.default + 1
    assert (params.cooccurrence.levels, params.composite.levels) == (co.default, co.default)
    params.cooccurrence.threshold = 0.5
    assert params.de_bonet.threshold == pytest.approx(
        addon.texsynth.get_method("de_bonet").param("threshold").default)
    assert params.multiscale_mrf.levels == mrf.default + 1


def test_the_operator_takes_the_chosen_methods_values_from_the_scene():
    generated_image(noise(32, 32))
    params = bpy.context.scene.texsynth.params
    params.cooccurrence.levels = 0  # below cooccurrence's minimum, 4
    fast_co = {"max_cliques": 4, "sweeps": 2}
    synthesize(source_image="source", method="MULTISCALE_MRF", width=24, height=16)
    with pytest.raises(RuntimeError, match="'levels' must be >= 4"):
        bpy.ops.texsynth.synthesize(source_image="source", method="COOCCURRENCE", width=24,
                                    height=16, **fast_co)
    assert [i.name for i in bpy.data.images] == ["source", "source_multiscale_mrf_0"]
    synthesize(source_image="source", method="COOCCURRENCE", width=24, height=16, levels=8,
               **fast_co)


def test_a_shared_parameter_name_is_one_property_covering_every_methods_spec(addon):
    core, properties = addon.texsynth, addon.operators.properties
    param = core.Param
    a = core.Method("a", "A", "", None, params=(param("size", int, 3, "", 1, 9),
                                                param("mode", str, "x", "", choices=("x", "y"))))
    b = core.Method("b", "B", "", None, params=(param("size", int, 5, "", 2, 20),
                                                param("mode", str, "y", "", choices=("y", "z"))))
    merged = properties.shared_params((a, b))
    assert (merged["size"].min, merged["size"].max, merged["size"].default) == (1, 20, 3)
    assert merged["mode"].choices == ("x", "y", "z")
    c = core.Method("c", "C", "", None, params=(param("size", float, 3.0, ""),))
    with pytest.raises(ValueError, match="'size' is int in method 'a' but float in 'c'"):
        properties.shared_params((a, b, c))


def test_every_method_runs_from_the_operator(addon):
    generated_image(noise(32, 32))
    for method in addon.texsynth.methods():
        image = synthesize(source_image="source", method=method.name.upper(), width=24,
                           height=16)
        assert tuple(image.size) == (24, 16) and np.isfinite(pixels_of(image)).all()


def test_new_image_and_node_take_over_the_source_nodes_links():
    source = generated_image(noise(48, 64), name="photo.png")
    before = pixels_of(source).copy()
    tree = material_with(source)
    old_links = links(tree)

    assert bpy.ops.texsynth.synthesize(width=96, height=80, **FAST) == {"FINISHED"}

    node = tree.nodes.active
    assert node.name != "source node" and node.bl_idname == "ShaderNodeTexImage" and node.select
    image = node.image
    assert image.name == "photo_heeger_bergen_0" and image.packed_file is not None
    assert tuple(image.size) == (96, 80) and not image.is_float
    assert image.colorspace_settings.name == "sRGB" and node.extension == "REPEAT"
    old = tree.nodes["source node"]
    assert old.image == source and source.name == "photo.png" and not old.select
    assert node.location.y < old.location.y
    np.testing.assert_array_equal(pixels_of(source), before)
    taken_over = [(node.name if a == "source node" else a, b, c, d) for a, b, c, d in old_links]
    assert links(tree) == sorted(taken_over + [("Texture Coordinate", "UV", node.name, "Vector")])


def test_same_seed_gives_the_same_texture_and_another_seed_another():
    source = generated_image(noise(40, 40))
    results = []
    for seed in (5, 5, 6):
        image = synthesize(source_image=source.name, width=48, height=40, seed=seed, **FAST)
        results.append(pixels_of(image))
    np.testing.assert_array_equal(results[0], results[1])
    assert not np.array_equal(results[0], results[2])


def test_a_named_image_gets_a_new_image_and_no_node():
    source = generated_image(noise(32, 32))
    image = synthesize(source_image=source.name, width=40, height=24, **FAST)
    assert [i.name for i in bpy.data.images] == ["source", "source_heeger_bergen_0"]
    assert tuple(image.size) == (40, 24) and not bpy.data.materials


def _file_source(tmp_path, kind):
    """(image, grey, alpha varies, float) for each kind of source a user may have."""
    if kind == "exr_grey":
        io.write_exr(tmp_path / "g.exr", noise(40, 48, 1, high=3.0))
        return bpy.data.images.load(str(tmp_path / "g.exr")), True, False, True
    if kind == "exr_hdr":
        io.write_exr(tmp_path / "h.exr", noise(40, 48, 3, high=8.0))
        return bpy.data.images.load(str(tmp_path / "h.exr")), False, False, True
    channels, bits = {"png8_grey": (1, 8), "png8_rgb": (3, 8), "png8_rgba": (4, 8),
                      "png16_rgb": (3, 16)}[kind]
    path = tmp_path / f"{kind}.png"
    io.write_png(path, noise(40, 48, channels), bits=bits)
    return bpy.data.images.load(str(path)), channels == 1, channels == 4, bits == 16


@pytest.mark.parametrize("kind", ["png8_grey", "png8_rgb", "png8_rgba", "png16_rgb", "exr_grey",
                                  "exr_hdr"])
def test_every_kind_of_source_gives_a_texture_like_it(tmp_path, kind):
    source, grey, alpha_varies, is_float = _file_source(tmp_path, kind)
    assert source.is_float == is_float
    tree = material_with(source)
    bpy.ops.texsynth.synthesize(width=56, height=36, **FAST)

    image = tree.nodes.active.image
    assert image.is_float == is_float and tuple(image.size) == (56, 36)
    got, want = pixels_of(image), pixels_of(source)
    assert np.isfinite(got).all()
    if grey:
        assert np.array_equal(got[:, :, 0], got[:, :, 1]) and np.array_equal(got[:, :, 0],
                                                                              got[:, :, 2])
    if alpha_varies:
        assert got[:, :, 3].std() > 0.1
    else:
        assert (got[:, :, 3] == 1).all()
    # Same marginal statistics in the same encoding: the texture looks like its source.
    np.testing.assert_allclose(got.mean(axis=(0, 1)), want.mean(axis=(0, 1))[:got.shape[2]],
                               rtol=0.05, atol=0.01)
    assert got.max() > 0.8 * want.max()


def test_a_flat_srgb_colour_comes_back_the_same_in_every_output(tmp_path):
    colour = np.array([204, 102, 51]) / 255
    generated_image(np.broadcast_to(colour, (32, 32, 3)), name="flat")
    linear = mathutils.Color(colour).from_srgb_to_scene_linear()
    for output, expected, is_float in (("PACK", colour, False), ("PNG", colour, False),
                                       ("EXR", linear, True)):
        image = synthesize(source_image="flat", width=24, height=16, output=output,
                           output_dir=str(tmp_path), **FAST)
        assert image.is_float == is_float, output
        got = pixels_of(image)
        np.testing.assert_allclose(got[:, :, :3], np.broadcast_to(expected, (16, 24, 3)),
                                   atol=0.5 / 255 if output != "EXR" else 1e-5, err_msg=output)


def test_the_exr_file_holds_exactly_the_images_linear_floats(tmp_path):
    source = generated_image(noise(32, 40, 3, high=6.0), float_buffer=True)
    image = synthesize(source_image=source.name, width=40, height=30, output="EXR",
                       output_dir=str(tmp_path), **FAST)
    path = bpy.path.abspath(image.filepath)
    assert path == str(tmp_path / "source_heeger_bergen_0.exr")
    assert image.is_float and not image.colorspace_settings.is_data
    written = io.read_exr(path)
    assert written.shape == (30, 40, 3) and written.max() > 1.0
    np.testing.assert_array_equal(written, pixels_of(image)[:, :, :3])


def test_a_png_of_a_float_source_holds_its_srgb_encoding(tmp_path):
    linear = noise(32, 32, 3, low=0.05, high=0.6)
    source = generated_image(linear, float_buffer=True)
    image = synthesize(source_image=source.name, width=32, height=24, output="PNG",
                       output_dir=str(tmp_path), **FAST)
    assert not image.is_float and image.colorspace_settings.name == "sRGB"
    encoded = io.read_png(bpy.path.abspath(image.filepath))
    np.testing.assert_allclose(encoded.mean(axis=(0, 1)),
                               color.linear_to_srgb(linear).mean(axis=(0, 1)), atol=0.02)


def test_non_color_data_stays_as_it_is(tmp_path):
    values = noise(32, 32)
    source = generated_image(values, colorspace="Non-Color")
    packed = synthesize(source_image=source.name, width=32, height=32, **FAST)
    saved = synthesize(source_image=source.name, width=32, height=32, output="EXR",
                       output_dir=str(tmp_path), **FAST)
    for image in (packed, saved):
        assert image.colorspace_settings.name == "Non-Color"
        np.testing.assert_allclose(pixels_of(image)[:, :, :3].mean(), values.mean(), atol=0.01)


def test_saved_files_never_replace_an_existing_file(tmp_path):
    io.write_png(tmp_path / "photo.png", noise(32, 32))
    taken = tmp_path / "photo_heeger_bergen_0.png"  # the name the first result would take
    taken.write_bytes(b"a file of the user's")
    bpy.data.images.load(str(tmp_path / "photo.png"))
    for _ in range(2):
        synthesize(source_image="photo.png", output="PNG", output_dir=str(tmp_path), width=32,
                   height=32, **FAST)
    assert taken.read_bytes() == b"a file of the user's"
    assert sorted(os.listdir(tmp_path)) == ["photo.png", "photo_heeger_bergen_0.png",
                                            "photo_heeger_bergen_0_1.png",
                                            "photo_heeger_bergen_0_2.png"]


def test_a_relative_directory_is_next_to_the_saved_blend(tmp_path):
    source = generated_image(noise(32, 32))
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    image = synthesize(source_image=source.name, width=32, height=32, output="PNG",
                       output_dir="//textures/", **FAST)
    assert image.filepath == "//textures/source_heeger_bergen_0.png"
    assert (tmp_path / "textures" / "source_heeger_bergen_0.png").is_file()
    assert tuple(image.size) == (32, 32) and image.has_data  # loads through the relative path


@pytest.mark.parametrize("call", ["EXEC_DEFAULT", "INVOKE_DEFAULT"])
def test_unset_properties_come_from_the_scene_settings(call):
    source = generated_image(noise(32, 32))
    tree = material_with(source)
    settings = bpy.context.scene.texsynth
    settings.width, settings.height = 72, 40
    settings.params.heeger_bergen.iterations = settings.params.heeger_bergen.scales = 2
    bpy.ops.texsynth.synthesize(call)
    assert tuple(tree.nodes.active.image.size) == (72, 40)
    bpy.ops.texsynth.synthesize(call, width=50)
    assert tuple(tree.nodes.active.image.size) == (50, 40)


def _wait(condition, seconds=60.0):
    end = time.monotonic() + seconds
    while not condition():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.01)


def test_the_worker_thread_reports_progress_and_cancels(addon):
    job_class, run = addon.operators.job.Task, addon.texsynth.synthesize
    job = job_class(run, noise(64, 64), 256, 256, iterations=100)
    job.start()
    _wait(lambda: job.fraction > 0 or job.done)
    job.cancel()
    _wait(lambda: job.done)
    assert job.cancelled and job.result is None and job.error is None

    job = job_class(run, noise(32, 32), 40, 24, **FAST)
    job.start()
    _wait(lambda: job.done)
    assert job.result.shape == (24, 40, 3) and job.fraction == 1.0

    job = job_class(run, noise(32, 32), 0, 24, **FAST)
    job.run()
    assert isinstance(job.error, ValueError) and job.result is None


def test_a_long_run_tells_the_time_left_from_its_progress(addon):
    job = addon.operators.job.Task(lambda progress: None)
    job.left.start, job.fraction = 100.0, 0.005
    assert job.time_left(now=101.0) == ""  # too early to say
    job.fraction = 0.25
    assert job.time_left(now=160.0) == ", 3:00 left"  # 60 s for a quarter: 180 s to go
    job = addon.operators.job.Task(lambda progress: None, predicted=600.0)
    job.left.start = 100.0
    assert job.time_left(now=160.0) == ", 9:00 left"  # the prediction, counted down
