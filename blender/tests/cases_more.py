"""Test cases: transfer, cancelling a precompute, undo of every operator, bad inputs."""

import os

import bmesh
import bpy
import numpy as np
from mathutils import Vector

import scene
from cases import (UNDO, check_undo, decal_setup, expect_error, precompute, spline_controls,
                   surface, wavg)

AXES = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
DIAGONALS = [(x, y, z) for x in (1, -1) for y in (1, -1) for z in (1, -1)]


def add_anchor_groups(obj, ids, prefix="wavg_anchor"):
    for k, i in enumerate(ids):
        obj.vertex_groups.new(name=f"{prefix}.{k:02d}").add([int(i)], 1.0, 'REPLACE')


def checker(size=64, cells=8):
    y, x = np.mgrid[0:size, 0:size] * cells // size
    rgba = np.zeros((size, size, 4), dtype=np.uint8)
    rgba[..., 0] = np.where((x + y) % 2 == 0, 230, 30)
    rgba[..., 1] = (255 * x // cells).astype(np.uint8)
    rgba[..., 2] = (255 * y // cells).astype(np.uint8)
    rgba[..., 3] = 255
    return rgba


def textured_source(tex):
    """A UV sphere with an image-texture material showing ``tex`` (row 0 at the top)."""
    src = scene.uv_sphere("src", 32, 16)
    h, w = tex.shape[:2]
    img = bpy.data.images.new("checker", width=w, height=h, alpha=True)
    img.pixels.foreach_set(np.ascontiguousarray(tex[::-1], dtype=np.float32).ravel() / 255.0)
    mat = bpy.data.materials.new("checker")
    mat.use_nodes = True
    node = mat.node_tree.nodes.new('ShaderNodeTexImage')
    node.image = img
    src.data.materials.append(mat)
    return src


def transfer_setup(groups=True):
    tex = checker()
    src = textured_source(tex)
    dst = scene.icosphere("dst", subdivisions=3, scale=(1.3, 1.0, 0.8))
    dst.location = (3.0, 0.0, 0.0)
    if groups:
        dirs = AXES + DIAGONALS
        add_anchor_groups(src, scene.nearest_vertices(src, dirs))
        add_anchor_groups(dst, scene.nearest_vertices(dst, dirs))
    return src, dst, tex


def corner_uv(obj):
    """Per-triangle corner UVs ``(m, 3, 2)`` of the active UV layer (loop triangles)."""
    me = obj.data
    me.calc_loop_triangles()
    loops = np.empty(len(me.loop_triangles) * 3, dtype=np.int32)
    me.loop_triangles.foreach_get("loops", loops)
    uv = np.empty(len(me.loops) * 2, dtype=np.float32)
    me.uv_layers.active.data.foreach_get("uv", uv)
    return uv.reshape(-1, 2)[loops.reshape(-1, 3)].astype(np.float64)


def anchor_ids(obj):
    names = sorted(g.name for g in obj.vertex_groups if g.name.startswith("wavg_anchor"))
    return np.array([scene.group_ids(obj, n)[0] for n in names])


def test_transfer(ctx):
    w = wavg()
    src, dst, tex = transfer_setup()
    precompute(src)
    precompute(dst)
    scene.activate(src, dst)
    bpy.ops.wavg.transfer(size=64)
    from wavg_blender import surfaces

    s_src, s_dst = surfaces.surface_of(src)[0], surfaces.surface_of(dst)[0]
    a_src, a_dst = anchor_ids(src), anchor_ids(dst)
    # Shape key: the source's vertices on the target (moved into the source's space).
    corr = w.correspond(s_src, s_dst, a_src, a_dst)
    valid = np.asarray(corr.valid, dtype=bool)
    invalid = scene.group_ids(src, "wavg_invalid")
    assert invalid == np.flatnonzero(~valid).tolist()
    assert valid.mean() > 0.5, f"only {valid.mean():.1%} of the source maps validly"
    key = src.data.shape_keys.key_blocks["wavg_transfer"]
    co = np.empty(len(key.data) * 3, dtype=np.float32)
    key.data.foreach_get("co", co)
    co = co.reshape(-1, 3).astype(np.float64)
    diag = scene.diagonal(dst)
    offset = np.array(dst.location)
    assert np.abs(co[valid] - (np.asarray(corr.xyz)[valid] + offset)).max() <= 1e-6 * diag
    assert scene.surface_distance(dst, co[valid] - offset) <= 1e-6 * diag
    assert np.all(np.isfinite(co)), "unmapped vertices were not filled"
    # UV layer on the target: the source's UVs at the corresponding points.
    layer = dst.data.uv_layers["wavg_transfer"]
    assert dst.data.uv_layers.active.name != "wavg_transfer", "the bake's UV layer changed"
    back = w.correspond(s_dst, s_src, a_dst, a_src)
    face = np.asarray(back.face)
    has = face >= 0
    uv_src = corner_uv(src)
    expect = np.zeros((len(face), 2))
    expect[has] = np.einsum("qc,qcd->qd", np.asarray(back.bary)[has], uv_src[face[has]])
    got = np.empty(len(dst.data.loops) * 2, dtype=np.float32)
    layer.data.foreach_get("uv", got)
    lv = np.empty(len(dst.data.loops), dtype=np.int32)
    dst.data.loops.foreach_get("vertex_index", lv)
    assert np.abs(got.reshape(-1, 2) - expect[lv]).max() <= 1e-6
    # The baked image equals wavg.transfer_texture's output.
    t_src = w.Surface(s_src.vertices, s_src.faces, uv=uv_src)
    t_src.load_embedding(surfaces.find_embedding(src))
    t_dst = w.Surface(s_dst.vertices, s_dst.faces, uv=corner_uv(dst))
    t_dst.load_embedding(surfaces.find_embedding(dst))
    ref = np.asarray(w.transfer_texture(t_src, tex, t_dst, a_src, a_dst, size=(64, 64)))
    img = bpy.data.images["wavg_transfer"]
    from wavg_blender import transfer_data

    baked = transfer_data.image_array(img)
    assert baked.shape == ref.shape, (baked.shape, ref.shape)
    assert np.array_equal(baked, ref), f"{int((baked != ref).any(axis=2).sum())} texels differ"
    assert (ref[..., 3] > 0).mean() > 0.2, "almost nothing was transferred"
    assert dst.material_slots[0].material.name == "wavg_transfer"


def test_precompute_cancel(ctx):
    from wavg_blender import op_precompute, surfaces

    ico = scene.icosphere("ico", subdivisions=4, scale=(1.0, 1.0, 0.5))
    job = op_precompute._Job(ico, 1000, 0)
    calls = []

    def stop(j):
        calls.append(j.stage)
        j.cancel = True  # what Esc does in the UI

    job.listener = stop
    job.run()
    assert calls, "the progress callback was never called"
    try:
        job.finish(ico)
    except Exception as e:
        assert "failed" in str(e) or "cancel" in str(e), str(e)
    else:
        raise AssertionError("a cancelled precompute finished")
    assert surfaces.find_embedding(ico) is None, "a cancelled precompute wrote a file"
    s = surfaces.new_surface(job.mesh)
    assert surfaces.load_cached(s, ico) is None, "a cancelled precompute wrote a cache entry"
    assert "wavg_key" not in ico


def test_undo(ctx):
    ico = scene.icosphere("ico", subdivisions=3)
    scene.activate(ico)
    check_undo("precompute", lambda: bpy.ops.wavg.precompute(*UNDO))
    precompute(bpy.data.objects["ico"])
    ico = bpy.data.objects["ico"]
    ids = spline_controls(ico)
    scene.select_in_order(ico, ids, edit=False)
    check_undo("place_point", lambda: bpy.ops.wavg.place_point(*UNDO))
    check_undo("surface_spline", lambda: bpy.ops.wavg.surface_spline(*UNDO))
    ico = bpy.data.objects["ico"]
    scene.select_in_order(ico, ids, edit=True)

    def in_edit_mode():
        bpy.ops.wavg.place_point(*UNDO)
        bpy.ops.object.mode_set(mode='OBJECT')

    check_undo("place_point in Edit mode", in_edit_mode)
    ico = bpy.data.objects["ico"]
    decal_setup(ico)
    scene.activate(ico)
    check_undo("decal_uv", lambda: bpy.ops.wavg.decal_uv(*UNDO))
    src, dst, _tex = transfer_setup()
    precompute(src)
    precompute(dst)
    scene.activate(src, dst)
    check_undo("transfer", lambda: bpy.ops.wavg.transfer(*UNDO, size=32))


def test_bad_inputs(ctx):
    fin = scene.fin()
    scene.activate(fin)
    expect_error("non-manifold precompute", bpy.ops.wavg.precompute, "not a valid manifold")
    expect_error("non-manifold point", bpy.ops.wavg.place_point, "not a valid manifold")

    ico = scene.icosphere("ico", subdivisions=2)
    scene.select_in_order(ico, [0, 5, 9], edit=False)
    for op in (bpy.ops.wavg.place_point, bpy.ops.wavg.surface_spline, bpy.ops.wavg.decal_uv):
        expect_error(f"{op.idname_py()} without embedding", op, "has no embedding")
    precompute(ico)
    ico = bpy.data.objects["ico"]

    scene.select_in_order(ico, [], edit=False)
    expect_error("point without selection", bpy.ops.wavg.place_point, "select at least one")
    scene.select_in_order(ico, [3], edit=True)
    expect_error("spline of one vertex", bpy.ops.wavg.surface_spline, "at least 2")
    bpy.ops.object.mode_set(mode='OBJECT')
    ico.data.vertices.foreach_set("select", [True] * len(ico.data.vertices))
    expect_error("spline without order", bpy.ops.wavg.surface_spline, "selection order")
    expect_error(
        "missing group", lambda: bpy.ops.wavg.place_point(group="nope"), "no vertex group 'nope'"
    )
    ico.vertex_groups.new(name="zero").add([1, 2], 0.0, 'REPLACE')
    scene.select_in_order(ico, [1, 2], edit=False)
    expect_error("zero weights", lambda: bpy.ops.wavg.place_point(group="zero"), "sum to zero")

    ico.vertex_groups.new(name="wavg_anchors").add([1, 2], 1.0, 'REPLACE')
    expect_error("decal of 2 anchors", bpy.ops.wavg.decal_uv, "too few anchors")
    ico.vertex_groups["wavg_anchors"].add([3, 4, 5], 1.0, 'REPLACE')
    expect_error("decal without uv attribute", bpy.ops.wavg.decal_uv, "no attribute 'wavg_uv'")

    src, dst, _tex = transfer_setup(groups=False)
    precompute(src)
    precompute(dst)
    scene.activate(src)
    expect_error("transfer without target", bpy.ops.wavg.transfer, "exactly one target")
    scene.activate(src, dst)
    ids = scene.nearest_vertices(src, AXES)
    add_anchor_groups(src, ids[:2])
    add_anchor_groups(dst, scene.nearest_vertices(dst, AXES)[:2])
    expect_error("transfer of 2 anchors", bpy.ops.wavg.transfer, "too few anchors")
    add_anchor_groups(src, ids[2:5], prefix="wavg_anchor.x")
    expect_error("mismatched groups", bpy.ops.wavg.transfer, "mismatched anchor groups")
    src.vertex_groups["wavg_anchor.00"].add([int(ids[5])], 1.0, 'REPLACE')
    expect_error("two-vertex group", bpy.ops.wavg.transfer, "holds 2 vertices")
    other = scene.icosphere("other", subdivisions=1)
    scene.activate(src, other)
    expect_error("transfer to a mesh without embedding", bpy.ops.wavg.transfer, "has no embedding")


def test_precompute_beside_blend(ctx):
    ico = scene.icosphere("ico", subdivisions=2)
    blend = os.path.join(ctx.tmp, "saved", "scene.blend")
    os.makedirs(os.path.dirname(blend), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=blend, check_existing=False)
    precompute(ico)
    from wavg_blender import surfaces

    path = surfaces.find_embedding(ico)
    assert path is not None and os.path.dirname(path) == os.path.dirname(blend), path
    assert os.path.isfile(path)
    assert [e["path"] for e in wavg().cache_entries(os.path.dirname(blend))] == [path]


def check_decal(obj, anchors):
    """The decal UV layer and ``wavg_invalid`` group of ``obj`` are wavg.decal's on
    ``anchors`` and their ``wavg_uv`` values."""
    me = obj.data
    flat = np.empty(len(me.vertices) * 2, dtype=np.float32)
    me.attributes["wavg_uv"].data.foreach_get("vector", flat)
    uv_attr = flat.reshape(-1, 2).astype(np.float64)
    uv_ref, valid_ref = wavg().decal(surface(obj), np.array(anchors), uv_attr[anchors])
    invalid = np.flatnonzero(~np.asarray(valid_ref)).tolist()
    assert scene.group_ids(obj, "wavg_invalid") == invalid, "wavg_invalid is not wavg.decal's"
    uv_ref = np.asarray(uv_ref)
    expect = np.where(np.isfinite(uv_ref), uv_ref, 0.0)
    loop_uv = np.empty(len(me.loops) * 2, dtype=np.float32)
    me.uv_layers["wavg_decal"].data.foreach_get("uv", loop_uv)
    lv = np.empty(len(me.loops), dtype=np.int32)
    me.loops.foreach_get("vertex_index", lv)
    err = np.abs(loop_uv.reshape(-1, 2) - expect[lv]).max()
    assert err <= 1e-6 * max(1.0, float(np.abs(expect).max())), f"UV layer off by {err:.2e}"


def test_decal_anchor_cache(ctx):
    """A decal run again on unchanged anchors reads them from memory; every edit of the
    anchor group (a member removed, one added, a weight set to 0) is seen."""
    from wavg_blender import group_cache

    ico = scene.icosphere("ico", subdivisions=3)
    precompute(ico)
    anchors, _uv = decal_setup(ico)
    scene.activate(ico)
    bpy.ops.wavg.decal_uv()
    check_decal(ico, anchors)
    hits = group_cache.HITS[0]
    bpy.ops.wavg.decal_uv()
    assert group_cache.HITS[0] == hits + 1, "the unchanged anchor group was read again"
    check_decal(ico, anchors)
    group = ico.vertex_groups["wavg_anchors"]
    group.remove([anchors[0]])
    added = scene.nearest_vertices(ico, [(0.3, 0.2, 1.0)])[0]
    assert added not in anchors
    group.add([added], 0.5, 'REPLACE')
    me = ico.data
    flat = np.empty(len(me.vertices) * 2, dtype=np.float32)
    me.attributes["wavg_uv"].data.foreach_get("vector", flat)
    flat[2 * added:2 * added + 2] = (0.5, 0.5)
    me.attributes["wavg_uv"].data.foreach_set("vector", flat)
    anchors = sorted(anchors[1:] + [added])
    for step in ("member removed and one added", "weight set to 0"):
        hits = group_cache.HITS[0]
        bpy.ops.wavg.decal_uv()
        assert group_cache.HITS[0] == hits, f"stale anchors after: {step}"
        check_decal(ico, anchors)
        group.add([anchors[-1]], 0.0, 'REPLACE')
        anchors = anchors[:-1]
    from wavg_blender import surfaces

    read = surfaces.mesh_input(ico)
    bpy.ops.wavg.decal_uv()
    assert surfaces.mesh_input(ico) is read, "the decal's own writes made the mesh be read again"
    invalid = scene.group_ids(ico, "wavg_invalid")
    assert invalid, "this decal marks no vertex"
    ico.vertex_groups["wavg_invalid"].remove(invalid[:1])
    bpy.ops.wavg.decal_uv()
    check_decal(ico, anchors)  # the edited wavg_invalid written again
    bpy.ops.ed.undo_push(message="before decal")
    bpy.ops.wavg.decal_uv(*UNDO)
    assert group_cache._ENTRIES, "the anchors read were not kept"
    bpy.ops.ed.undo()
    assert not group_cache._ENTRIES, "entries survived an undo"


def bmesh_edit_move(obj, v, offset):
    """Moves vertex ``v`` of ``obj`` (in Edit mode) by ``offset`` as a tool does."""
    bm = bmesh.from_edit_mesh(obj.data)
    bm.verts.ensure_lookup_table()
    bm.verts[v].co += Vector(offset)
    bmesh.update_edit_mesh(obj.data)


def test_mesh_memo(ctx):
    """An operator run again reuses the mesh it read (no read, no hash); every edit of the
    geometry, in Object and Edit mode, and undo are seen: an edited mesh has no embedding,
    and the mesh restored has its own again."""
    from wavg_blender import surfaces

    ico = scene.icosphere("ico", subdivisions=3)
    precompute(ico)
    ico = bpy.data.objects["ico"]
    scene.select_in_order(ico, [0, 5, 9], edit=False)
    first = surfaces.mesh_input(ico)
    assert surfaces.mesh_input(ico) is first, "an unchanged mesh was read again"
    bpy.ops.wavg.place_point()
    assert surfaces.mesh_input(ico) is first, "placing a point made the mesh be read again"

    me = ico.data
    co = me.vertices[7].co.copy()
    me.vertices[7].co.x += 0.05
    me.update()
    expect_error("point on a moved vertex", bpy.ops.wavg.place_point, "has no embedding")
    me.vertices[7].co = co
    me.update()
    bpy.ops.wavg.place_point()

    scene.select_in_order(ico, [0, 5, 9], edit=True)
    edit = surfaces.mesh_input(ico)
    assert surfaces.mesh_input(ico) is edit, "an unchanged mesh was read again in Edit mode"
    bpy.ops.wavg.place_point()
    bmesh_edit_move(ico, 7, (0.05, 0.0, 0.0))
    moved = surfaces.mesh_input(ico)  # synced out of Edit mode: the snapshot sees the move
    assert moved is not edit and moved.key != edit.key, "a move in Edit mode was not seen"
    expect_error("point on a vertex moved in Edit mode", bpy.ops.wavg.place_point,
                 "has no embedding")
    bmesh_edit_move(ico, 7, (-0.05, 0.0, 0.0))
    bpy.ops.wavg.place_point()
    bpy.ops.object.mode_set(mode='OBJECT')

    bpy.ops.ed.undo_push(message="before the move")
    me = bpy.data.objects["ico"].data
    me.vertices[7].co.x += 0.05
    me.update()
    bpy.ops.ed.undo_push(message="moved")
    expect_error("point on a moved vertex", bpy.ops.wavg.place_point, "has no embedding")
    bpy.ops.ed.undo()
    scene.select_in_order(bpy.data.objects["ico"], [0, 5, 9], edit=False)
    bpy.ops.wavg.place_point()


def test_read_ahead(ctx):
    """The embedding recorded on a mesh is read in a worker thread when the mesh becomes
    active: the first operator on it takes that surface instead of reading it, with the
    same result; a mesh without embedding starts no read, nor does a second activation."""
    from wavg_blender import activation, background, surfaces

    ico = scene.icosphere("ico", subdivisions=3)
    precompute(ico)
    ico = bpy.data.objects["ico"]
    other = scene.icosphere("other", subdivisions=1)
    surfaces.forget_all()
    started = background.STARTED[0]
    scene.activate(other)
    assert not activation.read_active(), "a read started for a mesh without embedding"
    scene.select_in_order(ico, [0, 5, 9], edit=False)
    assert activation.read_active(), "no read started for the active mesh"
    assert not activation.read_active(), "a second read of the same mesh started"
    assert background.STARTED[0] == started + 1
    loads = surfaces.LOADS[0]
    bpy.ops.wavg.place_point()
    assert surfaces.LOADS[0] == loads, "the operator read the embedding again"
    ahead = np.array(bpy.context.view_layer.objects["wavg_point"].location)
    surfaces.forget_all()
    bpy.ops.wavg.place_point()
    assert surfaces.LOADS[0] > loads, "the embedding was not read without the read ahead"
    again = np.array(bpy.context.view_layer.objects["wavg_point.001"].location)
    assert np.array_equal(ahead, again), f"read ahead {ahead}, read by the operator {again}"


TESTS = [test_transfer, test_precompute_cancel, test_undo, test_bad_inputs,
         test_precompute_beside_blend, test_decal_anchor_cache, test_mesh_memo,
         test_read_ahead]
