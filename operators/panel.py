"""The TexSynth tab in the Shader Editor's sidebar."""

import bpy

from . import properties, source


class SidebarPanel:
    """Mixin of the panels of the TexSynth tab of the Shader Editor's sidebar."""

    bl_space_type = "NODE_EDITOR"
    bl_region_type = "UI"
    bl_category = "TexSynth"

    @classmethod
    def poll(cls, context):
        return getattr(context.space_data, "tree_type", "") == "ShaderNodeTree"


class TEXSYNTH_PT_synthesize(SidebarPanel, bpy.types.Panel):
    bl_label = "Texture Synthesis"

    def draw(self, context):
        layout = self.layout
        try:
            found = source.find_source(context)
            layout.label(text=found.image, icon="IMAGE_DATA")
        except ValueError as error:
            layout.label(text=str(error), icon="INFO")
        properties.draw_settings(layout, context.scene.texsynth)
        layout.operator("texsynth.synthesize", icon="TEXTURE")
        layout.operator("texsynth.make_tileable", icon="MOD_ARRAY")


classes = (TEXSYNTH_PT_synthesize,)

register, unregister = bpy.utils.register_classes_factory(classes)
