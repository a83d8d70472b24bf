"""Plane orientation from a photo (shape from texture, Forsyth & Ponce, sec. 11.4.1): estimate,
align the camera, rectify. The work is the core's ``texsynth.plane``.

* ``texsynth.estimate_plane`` reads a photo (the operator's ``image``, else the Image Editor's
  image, else the panel's photo, else the active Image Texture node's image) and stores slant,
  tilt (radians), focal length (the scene camera's when asked, else the photo file's EXIF,
  else estimated; ``focal_source`` says which) and confidence in ``scene.texsynth.plane``
  (``properties.TEXSYNTH_PG_plane``).
* ``texsynth.plane_from_rectangle`` stores the plane of a rectangle the user marks on it instead
  (``corners``: x1, y1, ..., x4, y4 in the photo's pixels, x right, y down; headless too), with
  the focal length from the scene camera or the EXIF as above, else from the rectangle's two
  vanishing points (``texsynth.plane.from_rectangle``); ``texsynth.place_corners`` takes the
  four corners as clicks in the Image Editor and runs it.
* ``texsynth.align_camera`` poses the scene camera (made if missing) so that the active object's
  local XY plane (world XY at the origin when nothing is active) is seen at that slant and tilt.
* ``texsynth.rectify`` writes the frontal view of the photo as a new image, ready for
  ``texsynth.synthesize``.

Align and rectify need a stored estimate: until there is one their ``poll()`` is False and says
so. An estimate that is a guess (``texsynth.plane.verdict``: confidence under 0.5) is said to be
one, and why, by the estimate's report and the panel; align and rectify then warn, ask first
when run from the interface, and offer ``frontal`` (slant 0: the photo taken square to the
surface) instead of applying the guessed slant.

Every check happens before anything changes: on error the file is as it was. The estimate works
on a copy of the photo reduced to at most 320 pixels on its longer side, so it is quick on a
photo of any size and the operators run synchronously (no :class:`job.JobOperator`).
"""

import math
import os

import bpy
import gpu
from gpu_extras.batch import batch_for_shader
from mathutils import Matrix

from ..texsynth import plane as estimate
from ..texsynth.io import exif_orientation
from . import output, pixels, source

DEFAULT_DISTANCE = 5.0


# --- which photo -------------------------------------------------------------------------------


def find_photo(context, name: str = ""):
    """The image to work on, or ``ValueError`` saying what to select."""
    if name:
        if name not in bpy.data.images:
            raise ValueError(f"No image named '{name}'")
        return bpy.data.images[name]
    space = getattr(context, "space_data", None)
    if space is not None and space.type == "IMAGE_EDITOR":
        if space.image is None:
            raise ValueError("The Image Editor shows no image: open the photo first")
        return space.image
    settings = context.scene.texsynth.plane
    if settings.photo is not None:
        return settings.photo
    try:
        return bpy.data.images[source.find_source(context).image]
    except ValueError as error:
        raise ValueError(f"No photo: pick one in the panel, or {str(error)[0].lower()}"
                         f"{str(error)[1:]}") from None


def camera_focal_px(scene, width: int, height: int) -> float:
    """The scene camera's focal length in pixels of a ``width`` x ``height`` photo."""
    camera = scene.camera
    if camera is None or camera.type != "CAMERA":
        raise ValueError("'Taken with Scene Camera' is on, but the scene has no camera")
    data = camera.data
    if data.type != "PERSP":
        raise ValueError(f"Camera '{camera.name}' is not a perspective camera")
    fit = data.sensor_fit
    sensor = data.sensor_height if fit == "VERTICAL" else data.sensor_width
    return estimate.focal_px_from_lens(data.lens, sensor, width, height, fit)


def _file(image) -> str | None:
    """The path of the image's file on disk, or None (packed, generated, missing)."""
    if image.source != "FILE" or image.packed_file is not None or not image.filepath:
        return None
    path = bpy.path.abspath(image.filepath, library=image.library)
    return path if os.path.isfile(path) else None


def file_focal_px(image) -> float | None:
    """The focal length in pixels from the EXIF of the image's file, if it has one on disk."""
    path = _file(image)
    return estimate.focal_px_from_file(path) if path else None


def file_orientation(image) -> int:
    """The EXIF ``Orientation`` of the image's file on disk (1: none, or no file).

    Blender shows and hands out a file's pixels as stored, whatever this says (a portrait phone
    photo, Orientation 6, lies on its side): the estimate, the camera and the rectified image
    all keep to the image as Blender shows it, so they agree with each other and with the
    camera's background; the estimate's report says when the file would be shown turned."""
    path = _file(image)
    try:
        return exif_orientation(path) if path else 1
    except OSError:
        return 1


def stored_estimate(settings, frontal: bool = False) -> estimate.PlaneEstimate:
    """The scene's estimate as the core's record; ``frontal``: seen square on (slant 0)."""
    if not settings.has_estimate:
        raise ValueError("No plane estimate yet: run Estimate Plane first")
    slant, tilt = math.degrees(settings.slant), math.degrees(settings.tilt) % 360.0
    if not 0.0 <= slant < 90.0:
        raise ValueError(f"Slant must be in [0, 90) degrees, it is {slant:.1f}")
    if frontal:
        slant = tilt = 0.0
    normal = estimate.normal_from_angles(slant, tilt)
    focal = settings.focal_px if settings.focal_px > 0 else None
    return estimate.PlaneEstimate(
        slant=slant, tilt=tilt, normal=tuple(float(c) for c in normal), focal_px=focal,
        focal_estimated=settings.focal_estimated,
        tilt_ambiguous_180=settings.tilt_ambiguous or frontal, confidence=settings.confidence,
        slant_uncertainty=math.degrees(settings.slant_uncertainty),
        tilt_uncertainty=math.degrees(settings.tilt_uncertainty),
        normal_uncertainty=math.degrees(settings.uncertainty), focal_uncertainty=None,
        anisotropy=settings.anisotropy, method="stored",
        image_size=(settings.image_width, settings.image_height),
        line_families=settings.line_families, lens_prior=settings.lens_prior and not frontal,
        lines_found=settings.lines_found)


def judged(settings) -> estimate.Verdict:
    """The stored estimate's verdict: a measurement or a guess, and why."""
    return estimate.verdict(stored_estimate(settings))


def _fail(operator, error):
    operator.report({"ERROR"}, str(error))
    return {"CANCELLED"}


class NeedsEstimate:
    """Mixin: ``poll()`` is False, saying why, until the scene holds a plane estimate. On a
    guess, ``invoke`` asks first (the reasons, and ``frontal`` to tick) and ``execute`` warns."""

    frontal: bpy.props.BoolProperty(
        name="Treat as Frontal", options={"SKIP_SAVE"},
        description="Ignore the estimated slant and tilt: the photo was taken square to the "
                    "surface (slant 0). Offered when the estimate is a guess")

    @classmethod
    def poll(cls, context):
        try:
            stored_estimate(context.scene.texsynth.plane)
        except ValueError as error:
            cls.poll_message_set(str(error))
            return False
        return True

    def invoke(self, context, event):
        if judged(context.scene.texsynth.plane).guess and not self.frontal:
            return context.window_manager.invoke_props_dialog(
                self, width=420, title=f"{self.bl_label}: the estimate is a guess")
        return self.execute(context)

    def draw(self, context):
        settings = context.scene.texsynth.plane
        layout = self.layout
        try:
            verdict = judged(settings)
        except ValueError:
            verdict = None
        if verdict is not None and verdict.guess:
            column = layout.column(align=True)
            column.label(text=f"The estimate is a guess (confidence {settings.confidence:.2f}):",
                         icon="ERROR")
            for reason in verdict.reasons:
                column.label(text=reason)
        layout.prop(self, "frontal")

    def warn_on_guess(self, settings, what: str) -> None:
        """A warning report when the stored estimate is a guess applied as it is."""
        verdict = judged(settings)
        if verdict.guess and not self.frontal:
            why = "; ".join(verdict.reasons)
            self.report({"WARNING"}, f"{what} a guessed slant of "
                                     f"{math.degrees(settings.slant):.0f}° ({why}); run again "
                                     "with 'Treat as Frontal' for slant 0")


# --- operators --------------------------------------------------------------------------------


def _photo_name():
    """The operators' Image property: which photo they read."""
    return bpy.props.StringProperty(
        name="Image", options={"SKIP_SAVE"},
        description="Name of the photo; empty: the Image Editor's image, the panel's photo or "
                    "the active Image Texture node's image")


class TEXSYNTH_OT_estimate_plane(bpy.types.Operator):
    """Estimate the slant and tilt of the textured plane in a photo (shape from texture)"""

    bl_idname = "texsynth.estimate_plane"
    bl_label = "Estimate Plane"
    bl_options = {"REGISTER", "UNDO"}

    image: _photo_name()

    def execute(self, context):
        settings = context.scene.texsynth.plane
        try:
            image = find_photo(context, self.image)
            photo, _ = pixels.read_exemplar(image)
            height, width = photo.shape[:2]
            focal, focal_source = None, "NONE"
            if settings.method == "AUTO":
                focal, focal_source = known_focal(context.scene, image, width, height)
            result = estimate.estimate_plane(photo, focal_px=focal,
                                             method=settings.method.lower())
        except ValueError as error:
            return _fail(self, error)
        turn = file_orientation(image)
        store(self, settings, image.name, result, focal_source,
              f". The file's EXIF turns it (Orientation {turn}) but Blender shows it as stored: "
              "the tilt is of the image as shown here"
              if turn != 1 and not image.is_dirty else "")  # dirty: maybe turned already
        return {"FINISHED"}


def known_focal(scene, image, width: int, height: int) -> tuple[float | None, str]:
    """The focal length in pixels the photo is known to have and where from: the scene
    camera's when the panel says so, else the file's EXIF, else (None, "NONE")."""
    settings = scene.texsynth.plane
    if settings.use_camera_focal:
        return camera_focal_px(scene, width, height), "CAMERA"
    if (focal := file_focal_px(image)) is not None:
        return focal, "EXIF"
    return None, "NONE"


def store(operator, settings, name: str, result, focal_source: str, note: str = "") -> None:
    """Keep a plane (``texsynth.plane.PlaneEstimate``) of the image ``name`` as the scene's
    estimate, for Align Camera and Rectify, and report it (``note`` ends the report)."""
    if result.focal_estimated:
        focal_source = "ESTIMATED"
    settings.has_estimate = True
    settings.image = name
    settings.image_width, settings.image_height = result.image_size
    settings.slant = math.radians(result.slant)
    settings.tilt = math.radians(result.tilt)
    settings.focal_px = result.focal_px or 0.0
    settings.focal_estimated = result.focal_estimated
    settings.focal_source = focal_source
    settings.tilt_ambiguous = result.tilt_ambiguous_180
    settings.confidence = result.confidence
    settings.uncertainty = math.radians(min(result.normal_uncertainty, 90.0))
    settings.slant_uncertainty = math.radians(min(result.slant_uncertainty, 90.0))
    settings.tilt_uncertainty = math.radians(min(result.tilt_uncertainty, 180.0))
    settings.anisotropy = result.anisotropy
    settings.line_families = result.line_families
    settings.lines_found = result.lines_found
    settings.lens_prior = result.lens_prior
    settings.from_rectangle = result.method == "rectangle"
    where = {"EXIF": " (EXIF)", "CAMERA": " (scene camera)", "ESTIMATED": " (estimated)"}
    lens = f", focal {result.focal_px:.0f} px{where.get(focal_source, '')}" \
        if result.focal_px else ", orthographic"
    either = " (or +180)" if result.tilt_ambiguous_180 else ""
    verdict = estimate.verdict(result)
    operator.report({"WARNING"} if verdict.guess else {"INFO"},
                    f"'{name}': slant {result.slant:.1f}°, tilt {result.tilt:.1f}°{either}"
                    f"{lens}, confidence {result.confidence:.2f}"
                    + (" (from the rectangle)" if result.method == "rectangle" else "")
                    + (f". {verdict.summary}" if verdict.guess or verdict.lens_prior else "")
                    + note)


class TEXSYNTH_OT_plane_from_rectangle(bpy.types.Operator):
    """The plane from a rectangle on it: its four corners, placed in order around it"""

    bl_idname = "texsynth.plane_from_rectangle"
    bl_label = "Plane from Rectangle"
    bl_options = {"REGISTER", "UNDO"}

    image: _photo_name()
    corners: bpy.props.FloatVectorProperty(
        name="Corners", size=8, options={"SKIP_SAVE"},
        description="x1, y1, ..., x4, y4: the rectangle's corners in order around it, in "
                    "pixels of the photo (x right, y down from its top-left pixel); all 0: the "
                    "panel's corners")

    def execute(self, context):
        settings = context.scene.texsynth.plane
        corners = list(self.corners) if any(self.corners) else list(settings.corners)
        try:
            image = find_photo(context, self.image)
            width, height = image.size
            if not width or not height:
                raise ValueError(f"Image '{image.name}' has no pixel data")
            focal, focal_source = known_focal(context.scene, image, width, height)
            result = estimate.from_rectangle([corners[i:i + 2] for i in range(0, 8, 2)],
                                             (height, width), focal_px=focal)
        except ValueError as error:
            return _fail(self, error)
        settings.corners = corners
        store(self, settings, image.name, result, focal_source)
        return {"FINISHED"}


def _image_pixel(context, image, x: int, y: int) -> tuple[float, float]:
    """The photo's pixel (x right, y down) under the region point (x, y)."""
    u, v = context.region.view2d.region_to_view(x, y)
    width, height = image.size
    return u * width - 0.5, (1.0 - v) * height - 0.5


class TEXSYNTH_OT_place_corners(bpy.types.Operator):
    """Click the four corners of a rectangle on the plane, in order around it (Esc cancels);
    the plane is then taken from it"""

    bl_idname = "texsynth.place_corners"
    bl_label = "Place Rectangle Corners"

    @classmethod
    def poll(cls, context):
        space = getattr(context, "space_data", None)
        if space is None or space.type != "IMAGE_EDITOR" or space.image is None:
            cls.poll_message_set("Open the photo in the Image Editor first")
            return False
        return True

    def invoke(self, context, event):
        self.points = []
        self.handle = bpy.types.SpaceImageEditor.draw_handler_add(
            _draw_corners, (self, context), "WINDOW", "POST_PIXEL")
        context.window_manager.modal_handler_add(self)
        context.workspace.status_text_set("Click corner 1 of 4 of a rectangle on the plane "
                                          "(in order around it); Esc or right-click cancels")
        return {"RUNNING_MODAL"}

    def _end(self, context):
        bpy.types.SpaceImageEditor.draw_handler_remove(self.handle, "WINDOW")
        context.workspace.status_text_set(None)
        context.area.tag_redraw()

    def modal(self, context, event):
        if event.type in {"ESC", "RIGHTMOUSE"} and event.value == "PRESS":
            self._end(context)
            return {"CANCELLED"}
        if event.type == "LEFTMOUSE" and event.value == "PRESS":
            image = context.space_data.image
            self.points.append(_image_pixel(context, image, event.mouse_region_x,
                                            event.mouse_region_y))
            context.area.tag_redraw()
            if len(self.points) < 4:
                context.workspace.status_text_set(f"Click corner {len(self.points) + 1} of 4")
                return {"RUNNING_MODAL"}
            self._end(context)
            flat = [c for point in self.points for c in point]
            bpy.ops.texsynth.plane_from_rectangle(image=image.name, corners=flat)
            return {"FINISHED"}
        return {"PASS_THROUGH"}


def _draw_corners(operator, context):
    """The corners placed so far and the sides between them, over the image."""
    image = context.space_data.image
    width, height = image.size
    points = [context.region.view2d.view_to_region((x + 0.5) / width, 1.0 - (y + 0.5) / height,
                                                   clip=False) for x, y in operator.points]
    if not points:
        return
    shader = gpu.shader.from_builtin("UNIFORM_COLOR")
    shader.uniform_float("color", (1.0, 0.6, 0.0, 1.0))
    gpu.state.point_size_set(8.0)
    batch_for_shader(shader, "POINTS", {"pos": points}).draw(shader)
    if len(points) > 1:
        batch_for_shader(shader, "LINE_STRIP", {"pos": points}).draw(shader)


class TEXSYNTH_OT_align_camera(NeedsEstimate, bpy.types.Operator):
    """Pose the scene camera so that the active plane (world XY if none) is seen as in the photo"""

    bl_idname = "texsynth.align_camera"
    bl_label = "Align Camera"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        scene = context.scene
        settings = scene.texsynth.plane
        try:
            est = stored_estimate(settings, self.frontal)
            photo = bpy.data.images.get(settings.image) if settings.add_background else None
            if settings.add_background and photo is None:
                raise ValueError(f"The estimated photo '{settings.image}' is gone: turn off "
                                 "'Photo as Background' or estimate again")
        except ValueError as error:
            return _fail(self, error)
        target = context.active_object
        plane = target.matrix_world.normalized() if target and target.type != "CAMERA" \
            else Matrix.Identity(4)
        camera = scene.camera
        if camera is not None and camera.type == "CAMERA":
            distance = (camera.matrix_world.translation - plane.translation).length
        else:
            data = bpy.data.cameras.new("Camera")
            camera = bpy.data.objects.new("Camera", data)
            scene.collection.objects.link(camera)
            scene.camera = camera
            distance = 0.0
        if distance < 1e-6:
            distance = DEFAULT_DISTANCE
        pose = estimate.camera_pose(est.slant, est.tilt, distance,
                                    [list(row) for row in plane])
        camera.matrix_world = Matrix(pose.tolist())
        width, height = est.image_size
        if width and height:
            scene.render.resolution_x, scene.render.resolution_y = width, height
            scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
        data = camera.data
        if est.focal_px is not None:
            data.type = "PERSP"
            data.shift_x = data.shift_y = 0.0
            fit = data.sensor_fit
            sensor = data.sensor_height if fit == "VERTICAL" else data.sensor_width
            data.lens = estimate.lens_from_focal_px(est.focal_px, sensor, width, height, fit)
        if photo is not None:
            data.show_background_images = True
            background = next((b for b in data.background_images if b.image == photo), None)
            if background is None:
                background = data.background_images.new()
                background.image = photo
            background.frame_method = "FIT"
        self.warn_on_guess(settings, "The camera is turned by")
        self.report({"INFO"}, f"Camera '{camera.name}' at {distance:.2f} from "
                              f"'{target.name if target else 'world origin'}'"
                              + (", square to it (treated as frontal)" if self.frontal else ""))
        return {"FINISHED"}


class TEXSYNTH_OT_rectify(NeedsEstimate, bpy.types.Operator):
    """Write the photo seen frontally (the plane's texture without perspective) as a new image"""

    bl_idname = "texsynth.rectify"
    bl_label = "Rectify Photo"
    bl_options = {"REGISTER", "UNDO"}

    image: bpy.props.StringProperty(
        name="Image", options={"SKIP_SAVE"},
        description="Name of the photo; empty: the image the estimate was made on")

    def execute(self, context):
        settings = context.scene.texsynth.plane
        try:
            est = stored_estimate(settings, self.frontal)
            name = self.image or settings.image
            if name not in bpy.data.images:
                raise ValueError(f"No image named '{name}'")
            image = bpy.data.images[name]
            photo, encoding = pixels.read_exemplar(image)
            frontal = estimate.rectify(photo, est)
        except ValueError as error:
            return _fail(self, error)
        stem = f"{bpy.path.clean_name(name.rsplit('.', 1)[0])}_rectified"
        result = output.create_image(frontal, encoding, output.Target("PACK", "", False, stem))
        settings.rectified = result.name
        space = getattr(context, "space_data", None)
        if space is not None and space.type == "IMAGE_EDITOR":
            space.image = result
        self.warn_on_guess(settings, "Rectified with")
        self.report({"INFO"}, f"Rectified '{name}' into '{result.name}' "
                              f"({result.size[0]} x {result.size[1]})"
                              + (" as a frontal photo" if self.frontal else ""))
        return {"FINISHED"}


classes = (TEXSYNTH_OT_estimate_plane, TEXSYNTH_OT_plane_from_rectangle,
           TEXSYNTH_OT_place_corners, TEXSYNTH_OT_align_camera, TEXSYNTH_OT_rectify)
register, unregister = bpy.utils.register_classes_factory(classes)
