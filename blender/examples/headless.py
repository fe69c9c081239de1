"""The add-on from a script, without a window:

    blender -b --factory-startup --python blender/examples/headless.py -- target/wavg_blender.zip

installs the add-on from the zip (into a temporary folder), makes a sphere, precomputes its
embedding, and places the weighted average of three vertices (weights from a vertex group).
"""

import os
import sys
import tempfile

import bmesh
import bpy

zip_path = os.path.abspath(sys.argv[sys.argv.index("--") + 1])
scripts = tempfile.mkdtemp()
os.makedirs(os.path.join(scripts, "addons"))
os.environ.setdefault("WAVG_BLENDER_CACHE", os.path.join(scripts, "cache"))
bpy.context.preferences.filepaths.script_directory = scripts
bpy.utils.refresh_script_paths()
bpy.ops.preferences.addon_install(filepath=zip_path, target='PREFS')
bpy.ops.preferences.addon_enable(module="wavg_blender")

bm = bmesh.new()
bmesh.ops.create_icosphere(bm, subdivisions=3, radius=1.0)
mesh = bpy.data.meshes.new("sphere")
bm.to_mesh(mesh)
sphere = bpy.data.objects.new("sphere", mesh)
bpy.context.scene.collection.objects.link(sphere)
bpy.context.view_layer.objects.active = sphere
sphere.select_set(True)

bpy.ops.wavg.precompute()  # the embedding, cached by the mesh's fingerprint

weights = sphere.vertex_groups.new(name="weights")
for vertex, weight in ((0, 0.5), (10, 0.3), (40, 0.2)):
    weights.add([vertex], weight, 'REPLACE')
    mesh.vertices[vertex].select = True  # the anchors: the selected vertices
bpy.ops.wavg.place_point(group="weights")
point = bpy.data.objects["wavg_point"]
print("wavg_point at", tuple(round(x, 4) for x in point.location))
