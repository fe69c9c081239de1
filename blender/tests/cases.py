"""The test cases: each builds its meshes, runs operators as a script does and checks the
results against the wavg package the add-on ships."""

import json
import math
import os
import subprocess
from dataclasses import dataclass

import bpy
import numpy as np

import scene

UNDO = ('EXEC_DEFAULT', True)  # run an operator as the UI does: it pushes its undo step


@dataclass
class Context:
    tmp: str
    cli: str | None


def wavg():
    import wavg as module

    return module


def precompute(obj):
    scene.activate(obj)
    bpy.ops.wavg.precompute()


def surface(obj):
    """The add-on's surface of ``obj`` (embedding from its cache)."""
    from wavg_blender import surfaces

    return surfaces.surface_of(obj)[0]


def cap_directions(polar_deg, count, axis=2):
    """``count`` unit directions on a circle at ``polar_deg`` from the +z axis."""
    out = []
    for i in range(count):
        t = 2 * math.pi * i / count
        s = math.sin(math.radians(polar_deg))
        out.append((s * math.cos(t), s * math.sin(t), math.cos(math.radians(polar_deg))))
    return out


def expect_error(ctx_msg, run, needle):
    """``run()`` fails with an error containing ``needle`` and changes nothing."""
    before = scene.snapshot()
    try:
        run()
    except RuntimeError as e:
        assert needle in str(e), f"{ctx_msg}: message {str(e)!r} lacks {needle!r}"
    else:
        raise AssertionError(f"{ctx_msg}: no error")
    changed = scene.diff(before, scene.snapshot())
    assert not changed, f"{ctx_msg}: the scene changed: {changed}"


def check_undo(label, run):
    """``run()`` (an operator with undo) changes the scene and one undo restores it."""
    bpy.ops.ed.undo_push(message="before " + label)
    before = scene.snapshot()
    run()
    assert scene.diff(before, scene.snapshot()), f"{label} changed nothing"
    bpy.ops.ed.undo()
    if bpy.context.object is not None and bpy.context.object.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    after = scene.snapshot()
    changed = scene.diff(before, after)
    assert not changed, f"undo of {label} left changes: " + "; ".join(
        f"{k}: {scene.describe_change(before.get(k), after.get(k))}" for k in changed)


# --- tests -------------------------------------------------------------------------------


def test_registered(ctx):
    for name in ("precompute", "place_point", "surface_spline", "decal_uv", "transfer"):
        assert getattr(bpy.ops.wavg, name).poll is not None
        cls = getattr(bpy.types, "WAVG_OT_" + name)
        assert {'REGISTER', 'UNDO'} <= set(cls.bl_options), name
    assert hasattr(bpy.types, "VIEW3D_PT_wavg") and hasattr(bpy.types, "VIEW3D_MT_wavg")
    for menu in ("VIEW3D_MT_object", "VIEW3D_MT_edit_mesh"):
        funcs = getattr(getattr(bpy.types, menu).draw, "_draw_funcs", [])
        assert any("wavg_blender" in getattr(f, "__module__", "") for f in funcs), menu


def test_precompute_cache(ctx):
    ico = scene.icosphere("ico")
    precompute(ico)
    from wavg_blender import surfaces

    # The embedding is an entry of the shared embedding cache in $WAVG_BLENDER_CACHE,
    # written by the Python door with the library's choice of options.
    folder = os.environ["WAVG_BLENDER_CACHE"]
    path = surfaces.find_embedding(ico)
    assert path is not None and os.path.isfile(path), f"no cache file {path}"
    assert os.path.dirname(path) == folder, path
    entries = [e for e in wavg().cache_entries(folder) if e["path"] == path]
    assert len(entries) == 1 and entries[0]["writer"] == "python", entries
    assert entries[0]["vertices"] == len(ico.data.vertices), entries
    assert ico["wavg_landmarks"] == 0 and ico["wavg_seed"] == 0
    # A fresh surface of the same mesh loads it: the cache is keyed by the mesh.

    surfaces.forget_all()
    s = surface(ico)
    assert s.embedding.shape == (len(ico.data.vertices), 8)


def test_place_point(ctx):
    w = wavg()
    ico = scene.icosphere("ico")
    precompute(ico)
    ids = scene.nearest_vertices(ico, [(1, 0, 0), (0, 1, 0), (0, 0, 1), (0.6, 0.6, 0.5)])
    group = ico.vertex_groups.new(name="w")
    weights = [0.1, 0.2, 0.3, 0.4]
    for i, x in zip(ids, weights):
        group.add([i], x, 'REPLACE')
    scene.select_in_order(ico, ids, edit=False)
    bpy.ops.wavg.place_point(group="w")
    empty = bpy.data.objects["wavg_point"]
    assert empty.type == 'EMPTY' and empty.parent == ico
    V, F = scene.arrays(ico)
    diag = scene.diagonal(ico)
    loc = np.array(empty.location)
    assert scene.surface_distance(ico, [loc]) <= 1e-6 * diag, "the Empty is off the surface"
    order = np.argsort(ids)
    anchors = np.array(ids)[order]
    wn = np.array(weights)[order] / sum(weights)
    ref = w.weighted_average(V, F, anchors, wn[None, :])
    assert bool(ref.ok[0])
    err = float(np.linalg.norm(loc - ref.xyz[0]))
    assert err <= 1e-6 * diag, f"Empty {loc} vs wavg.weighted_average {ref.xyz[0]} ({err:.2e})"
    # New weights: the depsgraph handler moves the Empty to the new average.
    group.add([ids[0]], 1.0, 'REPLACE')
    ico.data.update()
    bpy.context.view_layer.update()
    wn2 = np.array([1.0, 0.2, 0.3, 0.4])[order] / 1.9
    ref2 = w.weighted_average(V, F, anchors, wn2[None, :])
    loc2 = np.array(empty.location)
    err2 = float(np.linalg.norm(loc2 - ref2.xyz[0]))
    assert err2 <= 1e-6 * diag, f"after new weights: {loc2} vs {ref2.xyz[0]} ({err2:.2e})"
    assert scene.surface_distance(ico, [loc2]) <= 1e-6 * diag
    # Uniform weights without a group, from Edit mode.
    scene.select_in_order(ico, ids, edit=True)
    bpy.ops.wavg.place_point()
    bpy.ops.object.mode_set(mode='OBJECT')
    uni = bpy.data.objects["wavg_point.001"]
    ref3 = w.weighted_average(V, F, anchors, np.full((1, 4), 0.25))
    assert np.linalg.norm(np.array(uni.location) - ref3.xyz[0]) <= 1e-6 * diag


def spline_controls(obj):
    return scene.nearest_vertices(
        obj, [(1, 0, 0.2), (0.3, 1, 0), (-1, 0.2, 0.1), (0, -1, 0.4), (0.5, 0.2, 1)]
    )


def test_surface_spline(ctx):
    w = wavg()
    ico = scene.icosphere("ico", subdivisions=4)
    precompute(ico)
    ids = spline_controls(ico)
    scene.select_in_order(ico, ids, edit=True)
    bpy.ops.wavg.surface_spline(degree=3, closed=False, bezier=False, samples=200)
    bpy.ops.object.mode_set(mode='OBJECT')
    curve = bpy.data.objects["wavg_spline"]
    diag = scene.diagonal(ico)
    pts = scene.curve_points(curve)
    s = surface(ico)
    faces, bary = s.vertex_points(np.array(ids))
    ref = w.spline(s, (faces, bary), samples=200, degree=3, closed=False, bezier=False)
    assert len(pts) == int(np.count_nonzero(ref.ok)) and len(pts) >= 190, len(pts)
    assert np.abs(pts - ref.xyz[ref.ok]).max() <= 1e-6 * diag, "curve differs from wavg.spline"
    assert scene.surface_distance(ico, pts) <= 1e-6 * diag, "a curve sample is off the surface"
    cvs = sorted((o for o in bpy.data.objects if o.get("wavg_curve") == curve),
                 key=lambda o: o["wavg_index"])
    assert len(cvs) == len(ids)
    # Drag a control point off the surface: it slides back onto it and the curve follows.
    cvs[1].location = np.array(cvs[1].location) * 1.2 + np.array([0.0, 0.0, 0.3])
    bpy.context.view_layer.update()
    moved = scene.curve_points(curve)
    assert np.abs(moved - pts).max() > 1e-3 * diag, "the curve did not follow its control point"
    assert scene.surface_distance(ico, [cvs[1].location]) <= 1e-6 * diag, "cv not on the surface"
    assert scene.surface_distance(ico, moved) <= 1e-6 * diag, "a moved sample is off the surface"
    f2 = np.array(curve["wavg_faces"])
    b2 = np.array(curve["wavg_bary"]).reshape(-1, 3)
    ref2 = w.spline(s, (f2, b2), samples=200, degree=3)
    assert np.abs(moved - ref2.xyz[ref2.ok]).max() <= 1e-6 * diag
    # The default sample count is wavg.spline's own (the library's), and live updates keep it.
    scene.select_in_order(ico, ids, edit=False)
    bpy.ops.wavg.surface_spline(degree=3)
    default = bpy.data.objects["wavg_spline.001"]
    ref3 = w.spline(s, (faces, bary), degree=3)
    assert default["wavg_samples"] == len(ref3.ok), (default["wavg_samples"], len(ref3.ok))
    assert len(scene.curve_points(default)) == int(np.count_nonzero(ref3.ok))
    # Other settings: closed, Bezier, degree 2, in Object mode (selection order kept).
    scene.select_in_order(ico, ids[:4], edit=False)
    bpy.ops.wavg.surface_spline(degree=2, closed=True, samples=120)
    closed = bpy.data.objects["wavg_spline.002"]
    assert closed.data.splines[0].use_cyclic_u
    assert scene.surface_distance(ico, scene.curve_points(closed)) <= 1e-6 * diag
    bpy.ops.wavg.surface_spline(bezier=True, samples=50)
    bez = bpy.data.objects["wavg_spline.003"]
    assert scene.surface_distance(ico, scene.curve_points(bez)) <= 1e-6 * diag


def write_obj(path, V, F):
    with open(path, "w") as f:
        f.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in V.tolist())
        f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F.tolist())


def decal_setup(obj):
    ids = scene.nearest_vertices(obj, cap_directions(35, 8))
    group = obj.vertex_groups.new(name="wavg_anchors")
    group.add(ids, 1.0, 'REPLACE')
    uv = scene.circle_uv(obj, ids)
    return sorted(ids), uv


def test_decal_uv(ctx):
    w = wavg()
    ico = scene.icosphere("ico", subdivisions=3)
    precompute(ico)
    anchors, uv_attr = decal_setup(ico)
    scene.activate(ico)
    bpy.ops.wavg.decal_uv()
    me = ico.data
    layer = me.uv_layers["wavg_decal"]
    n = len(me.vertices)
    invalid = scene.group_ids(ico, "wavg_invalid")
    fraction = 1.0 - len(invalid) / n
    s = surface(ico)
    uv_ref, valid_ref = w.decal(s, np.array(anchors), uv_attr[anchors].astype(np.float64))
    assert invalid == np.flatnonzero(~np.asarray(valid_ref)).tolist()
    loop_uv = np.empty(len(me.loops) * 2, dtype=np.float32)
    layer.data.foreach_get("uv", loop_uv)
    lv = np.empty(len(me.loops), dtype=np.int32)
    me.loops.foreach_get("vertex_index", lv)
    uv_ref = np.asarray(uv_ref)
    ok_ref = np.isfinite(uv_ref).all(axis=1)
    expect = np.where(ok_ref[:, None], uv_ref, 0.0)[lv]
    got = loop_uv.reshape(-1, 2)
    scale = max(1.0, float(np.abs(expect).max()))
    err = np.abs(got - expect).max()
    assert err <= 1e-6 * scale, f"UV layer vs wavg.decal: {err:.2e} (|uv| up to {scale:.1f})"
    assert 0.05 < fraction < 1.0, f"valid fraction {fraction}: the test decal is not local"
    if not ctx.cli:
        print("    (no --wavg-cli: decal compared with wavg.decal only)")
        assert abs(fraction - float(np.mean(valid_ref))) < 1e-12
        return
    V, F = scene.arrays(ico)
    d = os.path.join(ctx.tmp, "decal")
    os.makedirs(d, exist_ok=True)
    write_obj(os.path.join(d, "m.obj"), V, F)
    from wavg_blender import surfaces

    emb = surfaces.find_embedding(ico)
    with open(os.path.join(d, "a.txt"), "w") as f:
        f.writelines(f"v {i}\n" for i in anchors)
    with open(os.path.join(d, "uv.txt"), "w") as f:
        f.writelines(f"{u!r} {v!r}\n" for u, v in uv_attr[anchors].astype(np.float64).tolist())
    out = subprocess.run(
        [ctx.cli, "decal", "--mesh", "m.obj", "--embedding", emb, "--anchors", "a.txt",
         "--uv", "uv.txt", "-o", "out.obj", "--json"],
        cwd=d, capture_output=True, text=True, check=True,
    )
    cli_fraction = json.loads(out.stdout)["valid_fraction"]
    assert abs(fraction - cli_fraction) < 1e-12, f"add-on {fraction} vs wavg decal {cli_fraction}"
    print(f"    valid fraction {fraction:.4f} = wavg decal's {cli_fraction:.4f}")


TESTS = [test_registered, test_precompute_cache, test_place_point, test_surface_spline,
         test_decal_uv]
