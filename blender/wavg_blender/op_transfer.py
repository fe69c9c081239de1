"""``wavg.transfer``: from the active mesh (source) to the selected one (target), with
anchors paired by vertex-group name (groups ``<prefix>*``, one vertex each): a shape key on
the source (its connectivity morphed onto the target), a UV layer on the target (the
source's UVs carried over), and the source's image texture baked through the
correspondence into a new image in the target's UV layout."""

import bpy
import numpy as np

from . import surfaces
from .common import ActiveMeshOperator, active_mesh, object_mode
from .errors import AddonError, describe, wavg
from .meshdata import uv_corners
from .op_decal import check_uv_layer_room, set_invalid_group, set_uv_layer
from .transfer_data import anchor_groups, harmonic_fill, image_array, set_image, source_image

NAME = "wavg_transfer"


def paired_anchors(src, dst, prefix):
    """Anchor vertex ids of the source and target paired by group name, sorted by name."""
    a, b = anchor_groups(src, prefix), anchor_groups(dst, prefix)
    only_a, only_b = sorted(set(a) - set(b)), sorted(set(b) - set(a))
    if only_a or only_b:
        parts = []
        if only_a:
            parts.append(f"'{src.name}' has {', '.join(only_a)} which '{dst.name}' lacks")
        if only_b:
            parts.append(f"'{dst.name}' has {', '.join(only_b)} which '{src.name}' lacks")
        raise AddonError("mismatched anchor groups: " + "; ".join(parts))
    names = sorted(a)
    if len(names) < 3:
        raise AddonError(
            f"too few anchors: {len(names)} paired vertex groups '{prefix}*' (one vertex "
            "each, same names on both meshes); a transfer needs at least 3"
        )
    return np.array([a[n] for n in names]), np.array([b[n] for n in names])


class WAVG_OT_transfer(ActiveMeshOperator, bpy.types.Operator):
    """Transfer from the active mesh to the selected one through corresponding anchor
    vertex groups: a shape key on the active mesh, a UV layer and a baked image on the
    selected one"""

    bl_idname = "wavg.transfer"
    bl_label = "Transfer to Selected"
    bl_options = {'REGISTER', 'UNDO'}

    anchors: bpy.props.StringProperty(
        name="Anchor groups",
        default="wavg_anchor",
        description="Prefix of the anchor vertex groups (one vertex each, paired by name)",
    )
    size: bpy.props.IntProperty(
        name="Image size", default=0, min=0, max=8192,
        description="Width and height of the baked image (0: the source image's size)",
    )

    def _run(self, context):
        src = active_mesh(context)
        targets = [o for o in context.selected_objects if o != src and o.type == 'MESH']
        if len(targets) != 1:
            raise AddonError(
                f"select exactly one target mesh besides the active (source) mesh "
                f"({len(targets)} selected)"
            )
        dst = targets[0]
        s_src, m_src = surfaces.surface_of(src)
        s_dst, m_dst = surfaces.surface_of(dst)
        a_src, a_dst = paired_anchors(src, dst, self.anchors)
        w = wavg()
        src_uv = uv_corners(src, m_src.tri_loops)
        dst_uv = uv_corners(dst, m_dst.tri_loops)
        image = source_image(src)
        if src_uv is not None:
            check_uv_layer_room(dst, NAME)
        try:
            fwd = w.correspond(s_src, s_dst, a_src, a_dst)
            back = w.correspond(s_dst, s_src, a_dst, a_src) if src_uv is not None else None
            baked = None
            if image is not None and src_uv is not None and dst_uv is not None:
                baked = w.transfer_texture(
                    surfaces.textured(m_src, src_uv[0][src_uv[1]]),
                    image_array(image),
                    surfaces.textured(m_dst, dst_uv[0][dst_uv[1]]),
                    a_src,
                    a_dst,
                    size=(self.size, self.size) if self.size else None,
                )
        except (w.WavgError, ValueError, TypeError) as e:
            raise AddonError(f"wavg cannot transfer '{src.name}' to '{dst.name}': {describe(e)}") from e

        valid = np.asarray(fwd.valid, dtype=bool)
        if not valid.any():
            raise AddonError(f"no vertex of '{src.name}' maps validly onto '{dst.name}'")
        to_src = src.matrix_world.inverted() @ dst.matrix_world
        mapped = harmonic_fill(np.asarray(fwd.xyz, dtype=np.float64), valid, m_src.F)
        mapped = mapped @ np.array(to_src.to_3x3()).T + np.array(to_src.translation)
        target_uv = None
        if back is not None:
            target_uv = carried_uv(back, src_uv)
        done = [f"shape key '{NAME}' on '{src.name}' ({valid.mean():.1%} valid)"]
        with object_mode(context):
            if src.data.shape_keys is None:
                src.shape_key_add(name="Basis", from_mix=False)
            key = src.data.shape_keys.key_blocks.get(NAME) or src.shape_key_add(
                name=NAME, from_mix=False
            )
            key.data.foreach_set("co", np.ascontiguousarray(mapped, dtype=np.float32).ravel())
            key.value = 1.0
            set_invalid_group(src, np.flatnonzero(~valid))
            src.data.update()
            if target_uv is not None:
                set_uv_layer(dst, NAME, target_uv)
                done.append(f"UV layer '{NAME}' on '{dst.name}'")
            if baked is not None:
                img = set_image(NAME, baked, dst, dst.data.uv_layers.active.name)
                done.append(f"image '{img.name}' ({img.size[0]}x{img.size[1]})")
        missing = []
        if src_uv is None:
            missing.append(f"'{src.name}' has no UV layer")
        if image is None:
            missing.append(f"'{src.name}' has no image texture")
        if dst_uv is None:
            missing.append(f"'{dst.name}' has no UV layer to bake into")
        self.report({'INFO'}, "; ".join(done) + (f" (skipped: {', '.join(missing)})" if missing else ""))
        return {'FINISHED'}


def carried_uv(back, src_uv):
    """Per target vertex: the source UV at its corresponding source point (interpolated
    over the source triangle's corners), ``(0, 0)`` where there is none."""
    loop_uv, tri_loops = src_uv
    face = np.asarray(back.face, dtype=np.int64)
    bary = np.asarray(back.bary, dtype=np.float64)
    has = face >= 0
    out = np.zeros((len(face), 2))
    corners = loop_uv[tri_loops[face[has]]]  # (q, 3, 2)
    out[has] = np.einsum("qc,qcd->qd", bary[has], corners)
    return out
