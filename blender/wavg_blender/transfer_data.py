"""The data side of ``wavg.transfer``: anchor vertex groups, filling the vertices that map
nowhere, and images as ``(H, W, 4)`` uint8 arrays (row 0 at the top, as wavg's textures;
Blender stores the bottom row first)."""

import bpy
import numpy as np

from .errors import AddonError


def anchor_groups(obj, prefix):
    """``{group name: vertex id}`` of the vertex groups of ``obj`` named ``prefix*``; each
    must hold exactly one vertex."""
    groups = {g.index: g.name for g in obj.vertex_groups if g.name.startswith(prefix)}
    members = {name: [] for name in groups.values()}
    if groups:
        for v in obj.data.vertices:
            for g in v.groups:
                name = groups.get(g.group)
                if name is not None and g.weight > 0.0:
                    members[name].append(v.index)
    out = {}
    for name, ids in members.items():
        if len(ids) != 1:
            raise AddonError(
                f"anchor group '{name}' of '{obj.name}' holds {len(ids)} vertices; each "
                "anchor group holds exactly one"
            )
        out[name] = ids[0]
    return out


def harmonic_fill(xyz, valid, F, iterations=500):
    """``xyz`` with the rows where ``valid`` is false replaced by the average of their
    neighbours (Jacobi iterations, the valid rows fixed), so that unmapped vertices follow
    the mapped ones smoothly."""
    out = np.where(valid[:, None], xyz, 0.0)
    free = ~valid
    if not free.any():
        return out
    n = len(xyz)
    edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    edges = np.concatenate([edges, edges[:, ::-1]])
    degree = np.bincount(edges[:, 0], minlength=n).astype(np.float64)
    degree[degree == 0] = 1.0
    out[free] = xyz[valid].mean(axis=0)
    for _ in range(iterations):
        acc = np.zeros_like(out)
        np.add.at(acc, edges[:, 0], out[edges[:, 1]])
        out[free] = acc[free] / degree[free, None]
    return out


def source_image(obj):
    """The first image of an Image Texture node in the materials of ``obj``, or ``None``."""
    for slot in obj.material_slots:
        mat = slot.material
        if mat is None or not mat.use_nodes:
            continue
        for node in mat.node_tree.nodes:
            if node.type == 'TEX_IMAGE' and node.image is not None and node.image.size[0] > 0:
                return node.image
    return None


def image_array(image):
    """``image`` as ``(H, W, 4)`` uint8, row 0 at the top."""
    w, h = image.size
    px = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(px)
    rgba = np.clip(np.rint(px.reshape(h, w, 4) * 255.0), 0, 255).astype(np.uint8)
    return np.ascontiguousarray(rgba[::-1])


def set_image(name, rgba, obj, uv_layer):
    """A new image ``name`` with the pixels ``rgba`` ``(H, W, 4)`` uint8 (row 0 at the top);
    a mesh without material gets one that shows it through ``uv_layer``."""
    h, w = rgba.shape[:2]
    img = bpy.data.images.new(name, width=w, height=h, alpha=True)
    img.pixels.foreach_set(np.ascontiguousarray(rgba[::-1], dtype=np.float32).ravel() / 255.0)
    img.pack()
    if len(obj.material_slots) == 0:
        mat = bpy.data.materials.new(name)
        mat.use_nodes = True
        nodes = mat.node_tree.nodes
        tex = nodes.new('ShaderNodeTexImage')
        tex.image = img
        uv = nodes.new('ShaderNodeUVMap')
        uv.uv_map = uv_layer
        bsdf = nodes.get("Principled BSDF")
        links = mat.node_tree.links
        links.new(uv.outputs["UV"], tex.inputs["Vector"])
        if bsdf is not None:
            links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
        obj.data.materials.append(mat)
    return img
