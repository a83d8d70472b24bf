"""Plane orientation from a photo: estimate, align the camera, rectify (``texsynth.plane``).

``texsynth.estimate_plane`` reads a photo (the operator's ``image``, else the Image Editor's
image, else the panel's photo, else the active Image Texture node's image) and stores slant, tilt
(radians), focal length (the scene camera's when asked, else the photo file's EXIF, else
estimated; ``focal_source`` says which) and confidence in ``scene.texsynth.plane``.
``texsynth.align_camera`` poses the scene camera (made if missing) so that the active object's
local XY plane (world XY at the origin when nothing is active) is seen at that slant and tilt;
``texsynth.rectify`` writes the frontal view of the photo as a new image, ready for
``texsynth.synthesize``. Every check happens before anything changes: on error the file is as it
was. The estimate takes a second or two on an image of any size (it works on a copy reduced to
320 pixels), so the operators run synchronously.
"""

import math
import os

import bpy
from mathutils import Matrix

from ..texsynth import plane as estimate
from . import output, pixels, properties, source

METHOD_ITEMS = (
    ("AUTO", "Auto", "Isotropy and homogeneity under perspective: the receding direction and, "
                     "when the focal length is unknown, an estimate of it"),
    ("ISOTROPY", "Isotropy", "Orthographic isotropy search: tilt known only up to 180 degrees"),
)
DEFAULT_DISTANCE = 5.0
FOCAL_SOURCES = (
    ("EXIF", "EXIF", "Read from the photo file's EXIF (the camera wrote it)"),
    ("CAMERA", "Scene Camera", "The scene camera's lens and sensor"),
    ("ESTIMATED", "Estimated", "Estimated from the photo's perspective"),
    ("NONE", "None (Orthographic)", "No perspective: the estimate is orthographic"),
)


class TEXSYNTH_PG_plane(bpy.types.PropertyGroup):
    """The last plane estimate and the estimate panels' settings (``scene.texsynth.plane``)."""

    photo: bpy.props.PointerProperty(
        name="Photo", type=bpy.types.Image,
        description="Photo of a textured plane (the 3D View panel's source; the Image Editor "
                    "uses the image it shows)")
    method: bpy.props.EnumProperty(name="Method", items=METHOD_ITEMS, default="AUTO",
                                   description="How the orientation is estimated")
    use_camera_focal: bpy.props.BoolProperty(
        name="Taken with Scene Camera",
        description="The photo was taken with the scene camera's lens and sensor: use its focal "
                    "length instead of the photo file's EXIF or an estimate")
    add_background: bpy.props.BoolProperty(
        name="Photo as Background", default=True,
        description="Show the photo as the camera's background image when aligning")
    has_estimate: bpy.props.BoolProperty(name="Has Estimate", options={"HIDDEN"})
    image: bpy.props.StringProperty(name="Estimated Image",
                                    description="Name of the image the estimate was made on")
    image_width: bpy.props.IntProperty(name="Width", subtype="PIXEL", options={"HIDDEN"})
    image_height: bpy.props.IntProperty(name="Height", subtype="PIXEL", options={"HIDDEN"})
    slant: bpy.props.FloatProperty(
        name="Slant", subtype="ANGLE", min=0.0, max=math.radians(89.9),
        description="Angle between the plane's normal and the camera's optical axis")
    tilt: bpy.props.FloatProperty(
        name="Tilt", subtype="ANGLE",
        description="Image direction in which the plane recedes, counter-clockwise from right")
    focal_px: bpy.props.FloatProperty(
        name="Focal Length", subtype="PIXEL", min=0.0,
        description="Focal length in pixels of the photo; 0: orthographic (unknown)")
    focal_estimated: bpy.props.BoolProperty(name="Focal Estimated", options={"HIDDEN"})
    focal_source: bpy.props.EnumProperty(
        name="Focal Length From", items=FOCAL_SOURCES, default="NONE",
        description="Where the estimate's focal length came from")
    tilt_ambiguous: bpy.props.BoolProperty(
        name="Tilt Ambiguous",
        description="The receding direction is not determined: tilt + 180 degrees fits as well")
    confidence: bpy.props.FloatProperty(name="Confidence", subtype="FACTOR", min=0.0, max=1.0,
                                        description="How far the estimate can be trusted")
    uncertainty: bpy.props.FloatProperty(
        name="Uncertainty", subtype="ANGLE", min=0.0,
        description="One-sigma uncertainty of the plane normal")
    rectified: bpy.props.StringProperty(name="Rectified Image",
                                        description="Name of the last rectified image")


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


def file_focal_px(image) -> float | None:
    """The focal length in pixels from the EXIF of the image's file, if it has one on disk."""
    if image.source != "FILE" or image.packed_file is not None or not image.filepath:
        return None
    path = bpy.path.abspath(image.filepath, library=image.library)
    return estimate.focal_px_from_file(path) if os.path.isfile(path) else None


def stored_estimate(settings) -> estimate.PlaneEstimate:
    """The scene's estimate as the core's record (uncertainties are not needed downstream)."""
    if not settings.has_estimate:
        raise ValueError("No plane estimate yet: run Estimate Plane first")
    slant, tilt = math.degrees(settings.slant), math.degrees(settings.tilt) % 360.0
    if not 0.0 <= slant < 90.0:
        raise ValueError(f"Slant must be in [0, 90) degrees, it is {slant:.1f}")
    normal = estimate.normal_from_angles(slant, tilt)
    focal = settings.focal_px if settings.focal_px > 0 else None
    return estimate.PlaneEstimate(
        slant=slant, tilt=tilt, normal=tuple(float(c) for c in normal), focal_px=focal,
        focal_estimated=settings.focal_estimated, tilt_ambiguous_180=settings.tilt_ambiguous,
        confidence=settings.confidence, slant_uncertainty=0.0, tilt_uncertainty=0.0,
        normal_uncertainty=math.degrees(settings.uncertainty), focal_uncertainty=None,
        anisotropy=0.0, method="stored", image_size=(settings.image_width, settings.image_height))


def _fail(operator, error):
    operator.report({"ERROR"}, str(error))
    return {"CANCELLED"}


# --- operators --------------------------------------------------------------------------------


class TEXSYNTH_OT_estimate_plane(bpy.types.Operator):
    """Estimate the slant and tilt of the textured plane in a photo (shape from texture)"""

    bl_idname = "texsynth.estimate_plane"
    bl_label = "Estimate Plane"
    bl_options = {"REGISTER", "UNDO"}

    image: bpy.props.StringProperty(
        name="Image", options={"SKIP_SAVE"},
        description="Name of the photo; empty: the Image Editor's image, the panel's photo or "
                    "the active Image Texture node's image")

    def execute(self, context):
        settings = context.scene.texsynth.plane
        try:
            image = find_photo(context, self.image)
            photo, _ = pixels.read_exemplar(image)
            height, width = photo.shape[:2]
            focal, source = None, "NONE"
            if settings.method == "AUTO":
                if settings.use_camera_focal:
                    focal, source = camera_focal_px(context.scene, width, height), "CAMERA"
                elif (focal := file_focal_px(image)) is not None:
                    source = "EXIF"
            result = estimate.estimate_plane(photo, focal_px=focal,
                                             method=settings.method.lower())
            if result.focal_estimated:
                source = "ESTIMATED"
        except ValueError as error:
            return _fail(self, error)
        settings.has_estimate = True
        settings.image = image.name
        settings.image_width, settings.image_height = width, height
        settings.slant = math.radians(result.slant)
        settings.tilt = math.radians(result.tilt)
        settings.focal_px = result.focal_px or 0.0
        settings.focal_estimated = result.focal_estimated
        settings.focal_source = source
        settings.tilt_ambiguous = result.tilt_ambiguous_180
        settings.confidence = result.confidence
        settings.uncertainty = math.radians(min(result.normal_uncertainty, 90.0))
        where = {"EXIF": " (EXIF)", "CAMERA": " (scene camera)", "ESTIMATED": " (estimated)"}
        lens = f", focal {result.focal_px:.0f} px{where.get(source, '')}" if result.focal_px \
            else ", orthographic"
        either = " (or +180)" if result.tilt_ambiguous_180 else ""
        self.report({"INFO"}, f"'{image.name}': slant {result.slant:.1f}°, tilt "
                              f"{result.tilt:.1f}°{either}{lens}, confidence "
                              f"{result.confidence:.2f}")
        return {"FINISHED"}


class TEXSYNTH_OT_align_camera(bpy.types.Operator):
    """Pose the scene camera so that the active plane (world XY if none) is seen as in the photo"""

    bl_idname = "texsynth.align_camera"
    bl_label = "Align Camera"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        scene = context.scene
        settings = scene.texsynth.plane
        try:
            est = stored_estimate(settings)
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
        self.report({"INFO"}, f"Camera '{camera.name}' at {distance:.2f} from "
                              f"'{target.name if target else 'world origin'}'")
        return {"FINISHED"}


class TEXSYNTH_OT_rectify(bpy.types.Operator):
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
            est = stored_estimate(settings)
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
        self.report({"INFO"}, f"Rectified '{name}' into '{result.name}' "
                              f"({result.size[0]} x {result.size[1]})")
        return {"FINISHED"}


# --- panels -----------------------------------------------------------------------------------


def draw_plane(layout, context, in_image_editor: bool) -> None:
    settings = context.scene.texsynth.plane
    layout.use_property_split = True
    layout.use_property_decorate = False
    if not in_image_editor:
        layout.prop(settings, "photo")
    layout.prop(settings, "method")
    row = layout.row()
    row.enabled = settings.method == "AUTO"
    row.prop(settings, "use_camera_focal")
    layout.operator("texsynth.estimate_plane", icon="VIEW_PERSPECTIVE")
    if not settings.has_estimate:
        return
    box = layout.box()
    box.label(text=f"Estimate of '{settings.image}'", icon="IMAGE_DATA")
    box.prop(settings, "slant")
    box.prop(settings, "tilt")
    if settings.tilt_ambiguous:
        box.label(text="Tilt may be off by 180°", icon="INFO")
    box.prop(settings, "focal_px")
    box.label(text="Focal length from: " + dict((k, n) for k, n, _ in FOCAL_SOURCES)[
        settings.focal_source], icon="CAMERA_DATA")
    box.prop(settings, "confidence")
    layout.prop(settings, "add_background")
    layout.operator("texsynth.align_camera", icon="CAMERA_DATA")
    column = layout.column(align=True)
    column.label(text="Rectify, then synthesize:")
    column.operator("texsynth.rectify", icon="IMAGE_PLANE")
    if settings.rectified in bpy.data.images:
        op = column.operator("texsynth.synthesize", icon="TEXTURE",
                             text=f"Synthesize from '{settings.rectified}'")
        op.source_image = settings.rectified


class PlanePanel:
    """Mixin of the two sidebar panels; ``in_image_editor``: the photo is the editor's image."""

    bl_label = "Plane from Texture"
    bl_region_type = "UI"
    bl_category = "TexSynth"
    in_image_editor = False

    def draw(self, context):
        draw_plane(self.layout, context, self.in_image_editor)


class TEXSYNTH_PT_plane_image(PlanePanel, bpy.types.Panel):
    bl_space_type = "IMAGE_EDITOR"
    in_image_editor = True


class TEXSYNTH_PT_plane_view3d(PlanePanel, bpy.types.Panel):
    bl_space_type = "VIEW_3D"


classes = (TEXSYNTH_PG_plane, TEXSYNTH_OT_estimate_plane, TEXSYNTH_OT_align_camera,
           TEXSYNTH_OT_rectify, TEXSYNTH_PT_plane_image, TEXSYNTH_PT_plane_view3d)
register_classes, unregister_classes = bpy.utils.register_classes_factory(classes)


def register():
    register_classes()
    properties.TEXSYNTH_PG_settings.plane = bpy.props.PointerProperty(type=TEXSYNTH_PG_plane)


def unregister():
    del properties.TEXSYNTH_PG_settings.plane
    unregister_classes()
