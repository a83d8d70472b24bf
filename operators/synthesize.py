"""``texsynth.synthesize``: a new seamless image and Image Texture node from a source image.

Properties the caller did not set are taken from the scene settings (``scene.texsynth``, the
panel). execute() runs synchronously: in background mode (``blender -b``, the bpy module), from
scripts and from the redo panel. invoke() (the panel's button) in the UI runs the numpy work in
a worker thread while a modal timer shows progress; Esc or right-click cancels. Every check
happens before anything is made, and the new image and node are made on the main thread only
after the work succeeded: on error or cancel the file is unchanged.
"""

import traceback

import bpy

from . import nodes, output, pixels, properties, source
from .job import Job

POLL_SECONDS = 0.1


class TEXSYNTH_OT_synthesize(bpy.types.Operator):
    """Synthesize a seamless texture of any size from the active Image Texture node's image into a
    new image and node"""

    bl_idname = "texsynth.synthesize"
    bl_label = "Synthesize Texture"
    bl_options = {"REGISTER", "UNDO"}

    # Further properties (method, size, seed, output, the methods' parameters) are added by
    # register() from the texsynth registry.
    source_image: bpy.props.StringProperty(
        name="Source Image",
        description="Name of the image to synthesize from; empty: the active Image Texture node's "
                    "image (a named image gets no new node)",
        options={"SKIP_SAVE"},
    )

    def draw(self, context):
        properties.draw_settings(self.layout, self)

    def execute(self, context):
        try:
            job, plan = self._prepare(context)
        except ValueError as error:
            return self._fail(error)
        job.run()
        return self._finish(job, plan)

    def invoke(self, context, event):
        if bpy.app.background:
            return self.execute(context)
        try:
            self._job, self._plan = self._prepare(context)
        except ValueError as error:
            return self._fail(error)
        self._job.start()
        wm = context.window_manager
        wm.progress_begin(0.0, 1.0)
        self._timer = wm.event_timer_add(POLL_SECONDS, window=context.window)
        wm.modal_handler_add(self)
        context.workspace.status_text_set("TexSynth: starting (Esc to cancel)")
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        job = self._job
        if event.type in {"ESC", "RIGHTMOUSE"} and event.value == "PRESS":
            job.cancel()  # the worker stops at its next progress report
            context.workspace.status_text_set("TexSynth: cancelling")
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        if not job.done:
            context.window_manager.progress_update(job.fraction)
            context.workspace.status_text_set(
                f"TexSynth: {job.message} ({job.fraction:.0%}); Esc to cancel")
            return {"PASS_THROUGH"}
        self._end_ui(context)
        return self._finish(job, self._plan)

    def cancel(self, context):
        self._job.cancel()
        self._end_ui(context)

    def _end_ui(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)

    def _prepare(self, context):
        """Check the input and copy the exemplar out of Blender; raises ``ValueError``."""
        properties.fill_unset(self, context.scene.texsynth)
        src = source.find_source(context, self.source_image)
        image = bpy.data.images[src.image]
        method = properties.selected_method(self)
        target = output.plan(self.output, self.output_dir, image.name, method.name, self.seed)
        exemplar, encoding = pixels.read_exemplar(image)
        params = {p.name: getattr(self, name) for p, name in properties.param_properties(method)}
        job = Job(exemplar, self.width, self.height, method.name, self.seed, params)
        return job, (src, encoding, target)

    def _finish(self, job, plan):
        """Make the new image and node from a finished job (main thread)."""
        if job.cancelled:
            self.report({"INFO"}, "Synthesis cancelled: nothing was created")
            return {"CANCELLED"}
        if job.error is not None:
            return self._fail(job.error)
        src, encoding, target = plan
        try:
            image = output.create_image(job.result, encoding, target)
        except OSError as error:
            return self._fail(error)
        tree, node = source.source_node(src)
        if node is not None:
            nodes.add_result_node(tree, node, image)
        elif src.node:
            self.report({"WARNING"}, f"Node '{src.node}' is gone: image '{image.name}' was made "
                                     "without a node")
        self.report({"INFO"}, f"Synthesized '{image.name}' ({image.size[0]} x {image.size[1]})")
        return {"FINISHED"}

    def _fail(self, error):
        if not isinstance(error, (ValueError, OSError)):
            traceback.print_exception(error)
            error = f"{type(error).__name__}: {error}"
        self.report({"ERROR"}, str(error))
        return {"CANCELLED"}


classes = (TEXSYNTH_OT_synthesize,)


def register():
    TEXSYNTH_OT_synthesize.__annotations__.update(properties.settings_annotations({"SKIP_SAVE"}))
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
