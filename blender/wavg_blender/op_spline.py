"""``wavg.surface_spline``: a curve ``wavg_spline`` on the surface through the selected
vertices in selection order. Each control point is an Empty ``wavg_cv`` (child of the
mesh); moving one slides it onto the surface and re-evaluates the curve (``live.py``)."""

import bpy
import numpy as np

from . import surfaces
from .common import ActiveMeshOperator, active_mesh, closest_points
from .errors import AddonError, describe, wavg
from .meshdata import selected_vertices


def evaluate(surface, faces, bary, settings):
    """The spline's samples (a ``wavg.Points``) for control points ``(faces, bary)``;
    ``samples`` 0 takes ``wavg.spline``'s default count."""
    w = wavg()
    degree, closed, bezier, samples = settings
    count = {"samples": samples} if samples else {}
    try:
        pts = w.spline(
            surface, (faces, bary), degree=degree, closed=closed, bezier=bezier, **count
        )
    except (w.WavgError, ValueError, TypeError) as e:
        raise AddonError(f"wavg cannot make this spline: {describe(e)}") from e
    if not pts.ok.any():
        raise AddonError("no sample of this spline has a point on the surface")
    return pts


def runs(ok):
    """``(start, stop)`` of each run of consecutive valid samples."""
    if ok.all():
        return [(0, len(ok))]
    edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(np.int8), [0]])))
    return list(zip(edges[::2], edges[1::2]))


def write_curve(curve, xyz, ok, closed):
    """Puts the samples into ``curve`` as poly splines (one per run of valid samples),
    reusing the existing spline when the point count is unchanged."""
    parts = runs(ok)
    cyclic = closed and len(parts) == 1 and parts[0] == (0, len(ok))
    if len(curve.splines) != len(parts) or any(
        len(sp.points) != b - a for sp, (a, b) in zip(curve.splines, parts)
    ):
        curve.splines.clear()
        for a, b in parts:
            curve.splines.new('POLY').points.add(int(b - a) - 1)
    for sp, (a, b) in zip(curve.splines, parts):
        xyzw = np.ones((b - a, 4), dtype=np.float32)
        xyzw[:, :3] = xyz[a:b]
        sp.points.foreach_set("co", xyzw.ravel())
        sp.use_cyclic_u = cyclic
    curve.update_tag()


def settings_of(curve_obj):
    return (
        int(curve_obj["wavg_degree"]),
        bool(curve_obj["wavg_closed"]),
        bool(curve_obj["wavg_bezier"]),
        int(curve_obj["wavg_samples"]),
    )


class WAVG_OT_surface_spline(ActiveMeshOperator, bpy.types.Operator):
    """Add a curve on the surface through the selected vertices in selection order, with
    control points that slide on the surface and update the curve live"""

    bl_idname = "wavg.surface_spline"
    bl_label = "Surface Spline"
    bl_options = {'REGISTER', 'UNDO'}

    degree: bpy.props.IntProperty(name="Degree", default=3, min=1, max=7)
    closed: bpy.props.BoolProperty(name="Closed", default=False)
    bezier: bpy.props.BoolProperty(
        name="Bézier", default=False, description="Control points form Bézier segments"
    )
    samples: bpy.props.IntProperty(
        name="Samples",
        default=0,
        min=0,
        max=100000,
        description="Samples along the curve (0: the default of wavg.spline, the library's)",
    )

    def _run(self, context):
        obj = active_mesh(context)
        surface, mesh = surfaces.surface_of(obj)
        ordered, selected = selected_vertices(obj)
        if len(selected) < 2:
            raise AddonError(
                "select at least 2 vertices, one by one (Shift-click) in the curve's order"
            )
        if len(ordered) != len(selected):
            raise AddonError(
                f"the selection order of {len(selected) - len(ordered)} of the "
                f"{len(selected)} selected vertices is unknown: select the control vertices "
                "one by one (Shift-click) in Edit mode"
            )
        control = np.array(ordered, dtype=np.int64)
        faces, bary = surface.vertex_points(control)
        settings = (self.degree, self.closed, self.bezier, self.samples)
        pts = evaluate(surface, faces, bary, settings)

        coll = (obj.users_collection[:1] or [context.scene.collection])[0]
        curve = bpy.data.curves.new("wavg_spline", 'CURVE')
        curve.dimensions = '3D'
        curve.bevel_depth = 0.004 * mesh.diagonal
        write_curve(curve, pts.xyz, np.asarray(pts.ok, dtype=bool), self.closed)
        curve_obj = bpy.data.objects.new("wavg_spline", curve)
        coll.objects.link(curve_obj)
        curve_obj.parent = obj
        curve_obj.matrix_parent_inverse.identity()
        curve_obj["wavg_mesh"] = obj
        curve_obj["wavg_key"] = mesh.key
        curve_obj["wavg_degree"] = self.degree
        curve_obj["wavg_closed"] = self.closed
        curve_obj["wavg_bezier"] = self.bezier
        curve_obj["wavg_samples"] = len(pts.ok)
        store_control(curve_obj, faces, bary)
        cvs = []
        for i, v in enumerate(control):
            cv = bpy.data.objects.new("wavg_cv", None)
            cv.empty_display_type = 'SPHERE'
            cv.empty_display_size = 0.012 * mesh.diagonal
            coll.objects.link(cv)
            cv.parent = obj
            cv.matrix_parent_inverse.identity()
            cv.location = mesh.V[v]
            cv["wavg_curve"] = curve_obj
            cv["wavg_index"] = i
            cvs.append(cv)
        # The control points sit on their vertices: the live update that follows the new
        # Empties finds them snapped already and the curve evaluated for them.
        _SNAPS[curve_obj.name] = (
            mesh.key,
            [tuple(c.location) for c in cvs],
            (np.asarray(faces, dtype=np.int64), np.asarray(bary, dtype=np.float64),
             mesh.V[control], np.zeros(len(control))),
        )
        ok = int(np.count_nonzero(pts.ok))
        self.report({'INFO'}, f"{curve_obj.name}: {ok} of {len(pts.ok)} samples on the surface")
        return {'FINISHED'}


def store_control(curve_obj, faces, bary):
    curve_obj["wavg_faces"] = np.asarray(faces, dtype=np.int64).tolist()
    curve_obj["wavg_bary"] = np.asarray(bary, dtype=np.float64).ravel().tolist()


def unchanged(curve_obj, faces, bary):
    """Whether the curve was last evaluated for the control points ``(faces, bary)``."""
    old_faces = np.array(curve_obj["wavg_faces"], dtype=np.int64)
    old_bary = np.array(curve_obj["wavg_bary"], dtype=np.float64).reshape(-1, 3)
    return np.array_equal(faces, old_faces) and np.array_equal(bary, old_bary)


def control_objects(curve_obj):
    """The curve's control Empties in order."""
    mesh_obj = curve_obj.get("wavg_mesh")
    if mesh_obj is None:
        return []
    cvs = [c for c in mesh_obj.children if c.get("wavg_curve") == curve_obj]
    return sorted(cvs, key=lambda c: c.get("wavg_index", 0))


# The last control points of each curve and where they snapped to, by curve name: while a
# control point is dragged only it is looked up again. The snap is a function of the point
# and the mesh (the key), so an entry never goes stale.
_SNAPS = {}


def snap(name, key, surface, points):
    """``((faces, bary, xyz, dist), moved)``: the closest surface point of each of
    ``points`` (object-space tuples), reusing the answers of points unchanged since the last
    call; ``moved`` tells whether any point changed."""
    old = _SNAPS.get(name)
    if old is not None and old[0] == key and len(old[1]) == len(points):
        moved = [i for i, (p, q) in enumerate(zip(points, old[1])) if p != q]
        if not moved:
            return old[2], False
        faces, bary, xyz, dist = (a.copy() for a in old[2])
    else:
        moved = range(len(points))
        faces, bary, xyz, dist = (
            np.empty(len(points), dtype=np.int64), np.empty((len(points), 3)),
            np.empty((len(points), 3)), np.empty(len(points)),
        )
    V, F, tree, _diagonal = surfaces.geometry(key, surface)
    for i, row in zip(moved, zip(*closest_points(tree, V, F, [points[i] for i in moved]))):
        faces[i], bary[i], xyz[i], dist[i] = row
    result = (faces, bary, xyz, dist)
    _SNAPS[name] = (key, points, result)
    return result, True


def follow_controls(curve_obj, force=False):
    """Slides the curve's control Empties onto the surface and re-evaluates the curve when
    one of them moved (or ``force``); True when the curve changed. This is the live update
    the depsgraph handler runs while a control point is dragged."""
    mesh_obj = curve_obj.get("wavg_mesh")
    key = curve_obj.get("wavg_key", "")
    surface = surfaces.cached(key)
    if mesh_obj is None or surface is None:
        return False
    cvs = control_objects(curve_obj)
    if len(cvs) < 2:
        return False
    to_local = None
    points = []
    for c in cvs:
        if c.parent == mesh_obj:
            points.append(tuple(c.location))
        else:
            if to_local is None:
                to_local = mesh_obj.matrix_world.inverted()
            points.append(tuple(to_local @ c.matrix_world.translation))
    (faces, bary, xyz, dist), moved = snap(curve_obj.name, key, surface, points)
    if not (force or moved) and unchanged(curve_obj, faces, bary):
        return False
    try:
        pts = evaluate(surface, faces, bary, settings_of(curve_obj))
    except AddonError:
        return False
    write_curve(curve_obj.data, pts.xyz, np.asarray(pts.ok, dtype=bool), curve_obj["wavg_closed"])
    store_control(curve_obj, faces, bary)
    tol = 1e-9 * surfaces.geometry(key, surface)[3]
    for c, p, d in zip(cvs, xyz, dist):
        if d > tol and c.parent == mesh_obj:
            c.location = p
    return True
