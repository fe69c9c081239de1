"""Menu entries (Object menu in Object mode, Mesh menu in Edit mode) and the N-panel "wavg"."""

import bpy

from . import surfaces

OPERATORS = (
    ("wavg.precompute", 'MOD_REMESH'),
    ("wavg.place_point", 'EMPTY_AXIS'),
    ("wavg.surface_spline", 'CURVE_BEZCURVE'),
    ("wavg.decal_uv", 'UV'),
    ("wavg.transfer", 'MOD_DATA_TRANSFER'),
)


class VIEW3D_MT_wavg(bpy.types.Menu):
    bl_idname = "VIEW3D_MT_wavg"
    bl_label = "wavg"

    def draw(self, context):
        for idname, icon in OPERATORS:
            self.layout.operator(idname, icon=icon)


class VIEW3D_PT_wavg(bpy.types.Panel):
    bl_idname = "VIEW3D_PT_wavg"
    bl_label = "wavg"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "wavg"

    def draw(self, context):
        layout = self.layout
        obj = context.view_layer.objects.active
        if obj is None or obj.type != 'MESH':
            layout.label(text="Make a mesh object active")
            return
        key = obj.get("wavg_key")
        ready = key is not None and (
            surfaces.cached(key) is not None or surfaces.find_embedding(obj) is not None
        )
        layout.label(
            text="Embedding: cached" if ready else "Embedding: none (precompute first)",
            icon='CHECKMARK' if ready else 'ERROR',
        )
        col = layout.column(align=True)
        for idname, icon in OPERATORS:
            col.operator(idname, icon=icon)


def menu_entry(self, context):
    self.layout.separator()
    self.layout.menu(VIEW3D_MT_wavg.bl_idname)


CLASSES = (VIEW3D_MT_wavg, VIEW3D_PT_wavg)
MENUS = ("VIEW3D_MT_object", "VIEW3D_MT_edit_mesh")


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    for name in MENUS:
        getattr(bpy.types, name).append(menu_entry)


def unregister():
    for name in MENUS:
        getattr(bpy.types, name).remove(menu_entry)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
