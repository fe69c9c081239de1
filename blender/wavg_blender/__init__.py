"""wavg for Blender: weighted averages on surfaces (points, surface splines, decal UVs,
shape/UV/texture transfer) through the wavg Python package shipped in ``vendor/``."""

bl_info = {
    "name": "wavg",
    "author": "wavg authors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > wavg; Object menu / Mesh menu > wavg",
    "description": "Weighted averages on surfaces: points, surface splines, decals, transfers",
    "category": "Mesh",
}

import bpy

from . import (activation, background, common, decal_memo, errors, group_cache, live, memo,
               meshdata, op_decal, op_point, op_precompute, op_spline, op_transfer, surfaces,
               transfer_data, ui)

OPERATORS = (
    op_precompute.WAVG_OT_precompute,
    op_point.WAVG_OT_place_point,
    op_spline.WAVG_OT_surface_spline,
    op_decal.WAVG_OT_decal_uv,
    op_transfer.WAVG_OT_transfer,
)


def register():
    errors.add_vendor_path()
    for cls in OPERATORS:
        bpy.utils.register_class(cls)
    ui.register()
    live.register()
    memo.register()
    activation.register()
    decal_memo.register()


def unregister():
    decal_memo.unregister()
    activation.unregister()
    memo.unregister()
    live.unregister()
    ui.unregister()
    for cls in reversed(OPERATORS):
        bpy.utils.unregister_class(cls)
    surfaces.forget_all()
