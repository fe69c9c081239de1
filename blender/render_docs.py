"""Renders the README's pictures of the add-on with Blender itself (Workbench, headless):

    cargo xtask blender-addon
    blender -b --factory-startup --python blender/render_docs.py -- \\
        --zip target/wavg_blender.zip --out docs/img

writes `blender_place_point.png`, `blender_surface_spline.png` and `blender_decal_uv.png`
(640 x 400). Each scene is built in code and the operators run as a script runs them.
`WAVG_DOCS_ONLY=decal` (any part of a picture's name) renders only that picture.
"""

import argparse
import math
import os
import sys
import tempfile

import bmesh
import bpy
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "tests"))

import scene  # noqa: E402


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="render_docs.py")
    p.add_argument("--zip", required=True)
    p.add_argument("--out", default="docs/img")
    return p.parse_args(argv)


def install(zip_path):
    tmp = tempfile.mkdtemp(prefix="wavg-blender-docs-")
    os.environ.setdefault("WAVG_BLENDER_CACHE", os.path.join(tmp, "cache"))
    scripts = os.path.join(tmp, "scripts")
    os.makedirs(os.path.join(scripts, "addons"))
    bpy.context.preferences.filepaths.script_directory = scripts
    bpy.utils.refresh_script_paths()
    bpy.ops.preferences.addon_install(filepath=os.path.abspath(zip_path), target='PREFS')
    bpy.ops.preferences.addon_enable(module="wavg_blender")


def blob():
    """A smooth lumpy sphere (subdivided icosphere with a few bumps), shaded smooth."""
    bm = bmesh.new()
    bmesh.ops.create_icosphere(bm, subdivisions=5, radius=1.0)
    for v in bm.verts:
        p = v.co.normalized()
        r = 1.0 + 0.18 * math.sin(3 * p.x + 1) * math.cos(2 * p.y) + 0.12 * p.z * p.z
        v.co = p * r
    for f in bm.faces:
        f.smooth = True
    obj = scene.link("blob", bm)
    obj.data.materials.append(material("clay", (0.75, 0.72, 0.68, 1.0)))
    return obj


def material(name, color):
    mat = bpy.data.materials.new(name)
    mat.diffuse_color = color
    return mat


def marker(at, parent, radius, color):
    """A small sphere (Empties do not render) at ``at`` in ``parent``'s space."""
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=16, v_segments=8, radius=radius)
    obj = scene.link("marker", bm)
    obj.parent = parent
    obj.location = at
    obj.data.materials.append(material("marker", color))
    return obj


def stage(out_path, color_type='MATERIAL'):
    """Camera, light and Workbench settings; renders to ``out_path``."""
    sc = bpy.context.scene
    cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    sc.collection.objects.link(cam)
    cam.location = (3.2, -3.6, 2.2)
    target = bpy.data.objects.new("target", None)
    sc.collection.objects.link(target)
    track = cam.constraints.new('TRACK_TO')
    track.target = target
    track.track_axis = 'TRACK_NEGATIVE_Z'
    track.up_axis = 'UP_Y'
    cam.data.lens = 40
    sc.camera = cam
    sc.render.engine = 'BLENDER_WORKBENCH'
    sc.display.shading.light = 'STUDIO'
    sc.display.shading.color_type = color_type
    sc.display.shading.show_cavity = False
    sc.render.resolution_x, sc.render.resolution_y = 640, 400
    sc.render.resolution_percentage = 100
    sc.render.image_settings.file_format = 'PNG'
    sc.render.image_settings.color_mode = 'RGB'
    sc.render.image_settings.compression = 100
    sc.render.filepath = out_path
    sc.display_settings.display_device = 'sRGB'
    sc.view_settings.view_transform = 'Standard'
    bpy.ops.render.render(write_still=True)
    print(f"wrote {out_path} ({os.path.getsize(out_path)} bytes)")


def anchors_on(obj, directions):
    return scene.nearest_vertices(obj, directions)


def place_point_picture(out):
    obj = blob()
    scene.activate(obj)
    bpy.ops.wavg.precompute()
    ids = anchors_on(obj, [(1, -0.6, 0.2), (0.2, -1, 0.6), (0.4, -0.4, 1), (1, -1, -0.5)])
    group = obj.vertex_groups.new(name="weights")
    for i, w in zip(ids, (0.55, 0.15, 0.15, 0.15)):
        group.add([i], w, 'REPLACE')
    scene.select_in_order(obj, ids, edit=False)
    bpy.ops.wavg.place_point(group="weights")
    V = scene.arrays(obj)[0]
    for i in ids:
        marker(V[i], obj, 0.045, (0.15, 0.35, 0.9, 1.0))
    marker(bpy.data.objects["wavg_point"].location, obj, 0.07, (0.95, 0.25, 0.1, 1.0))
    stage(os.path.join(out, "blender_place_point.png"))


def surface_spline_picture(out):
    obj = blob()
    scene.activate(obj)
    bpy.ops.wavg.precompute()
    ids = anchors_on(obj, [(1, 0.2, -0.3), (0.8, -1, 0.1), (0.1, -1, 0.9), (0.9, -0.2, 1),
                           (1.2, -1, 1.1)])
    scene.select_in_order(obj, ids, edit=False)
    bpy.ops.wavg.surface_spline(degree=3, closed=True, samples=400)
    curve = bpy.data.objects["wavg_spline"]
    curve.data.bevel_depth = 0.02
    curve.data.materials.append(material("curve", (0.95, 0.3, 0.1, 1.0)))
    V = scene.arrays(obj)[0]
    for i in ids:
        marker(V[i], obj, 0.05, (0.15, 0.35, 0.9, 1.0))
    stage(os.path.join(out, "blender_surface_spline.png"))


def checker_colors(obj, layer, invalid, cells=4):
    """A per-corner colour attribute "decal": a checkerboard in the UV layer's coordinates,
    clay where a corner's vertex is in ``invalid`` (Workbench shows it as "Attribute")."""
    me = obj.data
    uv = np.empty(len(me.loops) * 2, dtype=np.float32)
    me.uv_layers[layer].data.foreach_get("uv", uv)
    uv = uv.reshape(-1, 2)
    lv = np.empty(len(me.loops), dtype=np.uint32)
    me.loops.foreach_get("vertex_index", lv)
    light = (np.floor(uv[:, 0] * cells) + np.floor(uv[:, 1] * cells)) % 2 == 0
    rgba = np.where(light[:, None], (0.95, 0.85, 0.3, 1.0), (0.2, 0.3, 0.6, 1.0))
    bad = np.isin(lv, np.array(sorted(invalid), dtype=np.int64))
    rgba[bad] = (0.75, 0.72, 0.68, 1.0)
    attr = me.color_attributes.new("decal", 'FLOAT_COLOR', 'CORNER')
    attr.data.foreach_set("color", rgba.astype(np.float32).ravel())
    me.color_attributes.active_color = attr
    index = list(me.color_attributes).index(attr)
    me.color_attributes.render_color_index = index
    me.color_attributes.active_color_index = index


def decal_uv_picture(out):
    obj = blob()
    scene.activate(obj)
    bpy.ops.wavg.precompute()
    centre = np.array([0.6, -0.8, 0.5])
    centre /= np.linalg.norm(centre)
    a = np.cross(centre, (0, 0, 1))
    a /= np.linalg.norm(a)
    b = np.cross(centre, a)
    dirs = [centre + 0.55 * (math.cos(t) * a + math.sin(t) * b) for t in
            np.linspace(0, 2 * math.pi, 8, endpoint=False)]
    ids = anchors_on(obj, dirs)
    obj.vertex_groups.new(name="wavg_anchors").add(ids, 1.0, 'REPLACE')
    scene.circle_uv(obj, ids)
    bpy.ops.wavg.decal_uv()
    checker_colors(obj, "wavg_decal", set(scene.group_ids(obj, "wavg_invalid")))
    stage(os.path.join(out, "blender_decal_uv.png"), color_type='VERTEX')


def main():
    args = parse_args()
    install(args.zip)
    os.makedirs(args.out, exist_ok=True)
    out = os.path.abspath(args.out)
    only = os.environ.get("WAVG_DOCS_ONLY")
    for picture in (place_point_picture, surface_spline_picture, decal_uv_picture):
        if only and only not in picture.__name__:
            continue
        scene.clear()
        for cam in list(bpy.data.cameras):
            bpy.data.cameras.remove(cam)
        picture(out)


main()
