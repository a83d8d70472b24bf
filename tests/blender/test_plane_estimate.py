"""Estimate Plane, Align Camera and Rectify headless: results land in the scene, and a failed
run changes nothing."""

import math

import bpy
import numpy as np
import pytest
from mathutils import Vector
from scenes import fingerprint, generated_image, material_with

from tests._exif import FOCAL_35MM, ORIENTATION, SHORT, with_exif
from tests._planes import noise_texture, photograph, spectral_slant
from texsynth.plane import angles_from_normal, focal_px_from_lens, normal_from_angles

SLANT, TILT, FOCAL = 50.0, 120.0, 280.0


@pytest.fixture(scope="module")
def photo_pixels():
    return photograph(noise_texture(n=256), SLANT, TILT, FOCAL, supersample=1)[:, :, None]


def _photo(pixels):
    return generated_image(np.clip(pixels, 0, 1), name="photo")


def _stored(scene, slant=SLANT, tilt=TILT, focal=FOCAL, image="photo"):
    settings = scene.texsynth.plane
    settings.has_estimate = True
    settings.image = image
    settings.image_width = settings.image_height = 256
    settings.slant, settings.tilt = math.radians(slant), math.radians(tilt)
    settings.focal_px = focal
    return settings


def test_estimate_plane_stores_the_orientation(photo_pixels):
    _photo(photo_pixels)
    scene = bpy.context.scene
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    camera.data.sensor_fit = "AUTO"
    camera.data.lens = FOCAL * camera.data.sensor_width / 256
    scene.texsynth.plane.use_camera_focal = True
    assert bpy.ops.texsynth.estimate_plane(image="photo") == {"FINISHED"}
    settings = scene.texsynth.plane
    assert settings.has_estimate and settings.image == "photo"
    assert settings.focal_px == pytest.approx(FOCAL, rel=1e-4)
    assert settings.focal_source == "CAMERA"
    got = (math.degrees(settings.slant), math.degrees(settings.tilt))
    n_true, n_got = normal_from_angles(SLANT, TILT), normal_from_angles(*got)
    assert math.degrees(math.acos(min(1.0, n_true @ n_got))) < 5.0
    assert 0.0 < settings.confidence <= 1.0
    assert not settings.tilt_ambiguous


def test_estimate_reads_the_focal_length_from_the_photo_files_exif(photo_pixels, tmp_path):
    """A phone JPEG: its 35 mm equivalent focal length is used, and the panel says so."""
    generated = _photo(photo_pixels)
    path = tmp_path / "phone.jpg"
    generated.filepath_raw = str(path)
    generated.file_format = "JPEG"
    generated.save()
    bpy.data.images.remove(generated)
    path.write_bytes(with_exif(path.read_bytes(), {}, {FOCAL_35MM: (SHORT, 33)}))
    bpy.data.images.load(str(path)).name = "photo"
    assert bpy.ops.texsynth.estimate_plane(image="photo") == {"FINISHED"}
    settings = bpy.context.scene.texsynth.plane
    assert settings.focal_source == "EXIF" and not settings.focal_estimated
    assert settings.focal_px == pytest.approx(33 / math.hypot(36, 24) * math.hypot(256, 256))
    got = (math.degrees(settings.slant), math.degrees(settings.tilt))
    n_true, n_got = normal_from_angles(SLANT, TILT), normal_from_angles(*got)
    assert math.degrees(math.acos(min(1.0, n_true @ n_got))) < 6.0


def test_a_turned_phone_jpeg_is_estimated_as_blender_shows_it(photo_pixels, tmp_path):
    """Blender ignores the EXIF orientation (a portrait phone photo lies on its side): the
    estimate keeps to the image as Blender shows it, so that the camera, its background and the
    rectified image agree (a tilt of the upright photo would be 90 degrees off)."""
    generated = _photo(photo_pixels[32:224])  # 256 x 192 as stored
    path = tmp_path / "portrait.jpg"
    generated.filepath_raw = str(path)
    generated.file_format = "JPEG"
    generated.save()
    bpy.data.images.remove(generated)
    path.write_bytes(with_exif(path.read_bytes(), {ORIENTATION: (SHORT, 6)}, {}))
    bpy.data.images.load(str(path)).name = "photo"
    assert tuple(bpy.data.images["photo"].size) == (256, 192)
    bpy.context.scene.texsynth.plane.use_camera_focal = False
    assert bpy.ops.texsynth.estimate_plane(image="photo") == {"FINISHED"}
    settings = bpy.context.scene.texsynth.plane
    assert (settings.image_width, settings.image_height) == (256, 192)
    got = normal_from_angles(math.degrees(settings.slant), math.degrees(settings.tilt))
    assert math.degrees(math.acos(min(1.0, normal_from_angles(SLANT, TILT) @ got))) < 10.0


def test_align_camera_poses_a_new_camera_on_the_active_plane(photo_pixels):
    _photo(photo_pixels)
    tree = material_with(bpy.data.images["photo"])
    plane = bpy.context.active_object
    plane.location = (1.0, 2.0, 0.5)
    plane.rotation_euler = (0.3, 0.0, 1.0)
    assert tree is not None and bpy.context.scene.camera is None
    settings = _stored(bpy.context.scene)
    settings.add_background = True
    assert bpy.ops.texsynth.align_camera() == {"FINISHED"}
    scene = bpy.context.scene
    camera = scene.camera
    assert camera is not None and camera.data.type == "PERSP"
    rotation = np.array(camera.matrix_world.to_3x3())
    normal = np.array(plane.matrix_world.to_3x3().normalized().col[2])
    slant, tilt = angles_from_normal(rotation.T @ normal)
    assert slant == pytest.approx(SLANT, abs=1e-3) and tilt == pytest.approx(TILT, abs=1e-3)
    to_plane = plane.matrix_world.translation - camera.matrix_world.translation
    assert (camera.matrix_world.to_3x3().inverted() @ to_plane).normalized().z == \
        pytest.approx(-1.0, abs=1e-6)
    focal_px = focal_px_from_lens(camera.data.lens, camera.data.sensor_width, 256, 256)
    assert focal_px == pytest.approx(FOCAL, rel=1e-5)
    assert (scene.render.resolution_x, scene.render.resolution_y) == (256, 256)
    assert [b.image.name for b in camera.data.background_images] == ["photo"]


def test_align_camera_keeps_an_existing_cameras_distance():
    scene = bpy.context.scene
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    camera.location = (0.0, -3.0, 4.0)
    settings = _stored(scene, focal=0.0)
    settings.add_background = False
    assert bpy.ops.texsynth.align_camera() == {"FINISHED"}
    assert set(bpy.data.objects) == {camera}
    assert camera.matrix_world.translation.length == pytest.approx(5.0)
    forward = camera.matrix_world.to_3x3() @ Vector((0, 0, -1))
    assert forward.angle(-camera.matrix_world.translation) == pytest.approx(0.0, abs=1e-6)


def test_rectify_makes_a_new_frontal_image(photo_pixels):
    image = _photo(photo_pixels)
    before = np.array(image.pixels[:])
    _stored(bpy.context.scene)
    assert bpy.ops.texsynth.rectify() == {"FINISHED"}
    settings = bpy.context.scene.texsynth.plane
    rectified = bpy.data.images[settings.rectified]
    assert rectified.name.startswith("photo_rectified") and rectified != image
    width, height = rectified.size
    assert min(width, height) >= 48
    np.testing.assert_array_equal(np.array(image.pixels[:]), before)
    values = np.array(rectified.pixels[:]).reshape(height, width, 4)[:, :, 0]
    assert spectral_slant(values) < 30.0  # frontal: 13-20


def _blank(pixels):
    generated_image(np.full((96, 96, 3), 0.5, np.float32), name="photo")


def _no_camera(pixels):
    _photo(pixels)
    bpy.context.scene.texsynth.plane.use_camera_focal = True


def _no_estimate(pixels):
    _photo(pixels)


def _estimate_for_a_deleted_photo(pixels):
    _stored(bpy.context.scene, image="gone")


CASES = {
    "estimate: unknown image": (lambda p: None, "estimate_plane", {"image": "nope"},
                                "No image named 'nope'"),
    "estimate: no photo at all": (lambda p: None, "estimate_plane", {}, "No photo"),
    "estimate: blank photo": (_blank, "estimate_plane", {"image": "photo"}, "no texture"),
    "estimate: camera focal without camera": (_no_camera, "estimate_plane", {"image": "photo"},
                                              "no camera"),
    "align: no estimate": (_no_estimate, "align_camera", {}, "No plane estimate"),
    "align: background photo gone": (_estimate_for_a_deleted_photo, "align_camera", {},
                                     "is gone"),
    "rectify: no estimate": (_no_estimate, "rectify", {}, "No plane estimate"),
    "rectify: photo gone": (_estimate_for_a_deleted_photo, "rectify", {}, "No image named"),
}


@pytest.mark.parametrize("case", CASES)
def test_failures_are_reported_and_change_nothing(photo_pixels, case):
    setup, operator, properties, message = CASES[case]
    setup(photo_pixels)
    scene = bpy.context.scene
    before = fingerprint(), _values(scene.texsynth.plane), scene.camera
    with pytest.raises(RuntimeError, match=message):
        getattr(bpy.ops.texsynth, operator)(**properties)
    assert (fingerprint(), _values(scene.texsynth.plane), scene.camera) == before


def _values(settings):
    return {name: getattr(settings, name) for name in settings.bl_rna.properties.keys()
            if name != "rna_type"}


@pytest.mark.parametrize("operator", ["align_camera", "rectify"])
def test_align_and_rectify_are_greyed_out_until_there_is_an_estimate(operator):
    op = getattr(bpy.ops.texsynth, operator)
    assert not op.poll()
    with pytest.raises(RuntimeError, match=r"poll\(\) No plane estimate yet: run Estimate Plane"):
        op()
    _stored(bpy.context.scene)
    assert op.poll()


def test_the_moments_baseline_is_not_offered():
    items = bpy.context.scene.texsynth.plane.bl_rna.properties["method"].enum_items
    assert [i.identifier for i in items] == ["AUTO", "ISOTROPY"]


# --- a guess is said to be one (issue 27) ------------------------------------------------------


def _guess(scene, image="photo"):
    """A frontal photo without a cue as the estimate reads it: 25 deg, as uncertain, no lines."""
    settings = _stored(scene, slant=25.0, tilt=70.0, focal=0.0, image=image)
    settings.confidence = 0.02
    settings.slant_uncertainty, settings.tilt_uncertainty = math.radians(15.0), math.pi
    settings.line_families, settings.anisotropy = 0, 1.4
    return settings


def _panel_labels(settings):
    """The 3D View's Plane from Texture panel as drawn for ``settings`` (the scene's)."""
    from test_panels import _draw
    return _draw("TEXSYNTH_PT_plane_view3d")


def test_the_panel_does_not_call_lines_it_ruled_out_absent():
    settings = _guess(bpy.context.scene)
    settings.lines_found = 2
    try:
        said = " / ".join(_panel_labels(settings).labels)
    finally:
        settings.lines_found = 0
    assert "lines found but not used" in said and "no straight lines" not in said


def test_the_panel_says_when_the_estimate_is_a_guess_and_why():
    settings = _guess(bpy.context.scene)
    layout = _panel_labels(settings)
    assert "A guess, not a measurement:" in layout.labels
    said = " / ".join(layout.labels)
    assert "no measurable slant" in said and "no straight lines" in said
    assert "texture anisotropic" in said
    # Align and rectify are offered as they are and as a frontal photo.
    assert layout.drawn.count("texsynth.align_camera") == 2
    assert layout.drawn.count("texsynth.rectify") == 2
    settings.confidence, settings.line_families = 0.9, 2
    settings.slant_uncertainty = math.radians(3.0)
    layout = _panel_labels(settings)
    assert "A guess, not a measurement:" not in layout.labels
    assert layout.drawn.count("texsynth.align_camera") == 1
    assert "No measurable slant: a frontal photo" not in layout.labels
    settings.slant = math.radians(0.5)  # measured to be frontal
    assert "No measurable slant: a frontal photo" in _panel_labels(settings).labels


def test_the_panel_says_when_frontal_rests_on_the_lens_prior():
    """Focal length unknown, lines parallel under every 13-200 mm lens: frontal, and the panel
    says under which assumption."""
    settings = _guess(bpy.context.scene)
    settings.slant, settings.confidence, settings.line_families = math.radians(1.0), 0.8, 2
    settings.slant_uncertainty = settings.uncertainty = math.radians(5.0)
    settings.lens_prior = True
    labels = _panel_labels(settings).labels
    assert "Frontal under a lens prior (13-200 mm eq.)" in labels
    assert "A guess, not a measurement:" not in labels
    settings.lens_prior = False
    assert "Frontal under a lens prior (13-200 mm eq.)" not in _panel_labels(settings).labels


def test_estimating_white_noise_stores_a_guess():
    """No plane cue at all: the estimate is stored, and what is stored says it is a guess."""
    generated_image(np.random.default_rng(1).random((128, 128, 3)).astype(np.float32),
                    name="photo")
    assert bpy.ops.texsynth.estimate_plane(image="photo") == {"FINISHED"}
    settings = bpy.context.scene.texsynth.plane
    assert settings.confidence < 0.5 and settings.line_families == 0
    assert "A guess, not a measurement:" in _panel_labels(settings).labels


@pytest.mark.parametrize("frontal", [False, True])
def test_align_camera_applies_a_guess_only_unless_told_to_treat_the_photo_as_frontal(frontal):
    scene = bpy.context.scene
    settings = _guess(scene)
    settings.add_background = False
    before = _values(settings)
    assert bpy.ops.texsynth.align_camera(frontal=frontal) == {"FINISHED"}
    rotation = np.array(scene.camera.matrix_world.to_3x3())
    slant, _ = angles_from_normal(rotation.T @ np.array([0.0, 0.0, 1.0]))
    assert slant == pytest.approx(0.0 if frontal else 25.0, abs=1e-3)
    assert _values(settings) == before  # the estimate itself is kept


def test_rectify_as_frontal_keeps_the_photo_as_it_is(photo_pixels):
    image = _photo(photo_pixels)
    _guess(bpy.context.scene)
    assert bpy.ops.texsynth.rectify(frontal=True) == {"FINISHED"}
    rectified = bpy.data.images[bpy.context.scene.texsynth.plane.rectified]
    assert rectified != image and tuple(rectified.size) == tuple(image.size)
    values = np.array(rectified.pixels[:]).reshape(256, 256, 4)[:, :, 0]
    original = np.array(image.pixels[:]).reshape(256, 256, 4)[:, :, 0]
    # The same pixels, softened by the rectifier's area filter (correlation 0.85 measured).
    assert np.corrcoef(values.ravel(), original.ravel())[0, 1] > 0.8
