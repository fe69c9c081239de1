"""The applications: splines, correspondence, decals, texture transfer, remeshing, rendering."""

import pathlib
import pickle
import subprocess
import sys

import numpy as np
import pytest

import wavg
from conftest import ROOT, torus


def test_spline_hits_its_ends(surface, anchors):
    c = wavg.spline(surface, anchors[:5], samples=40)
    assert c.xyz.shape == (40, 3) and c.ok.all()
    V = surface.vertices
    assert np.allclose(c.xyz[0], V[anchors[0]], atol=1e-9)
    assert np.allclose(c.xyz[-1], V[anchors[4]], atol=1e-9)
    closed = wavg.spline(surface, anchors[:5], samples=40, closed=True)
    bez = wavg.spline(surface, anchors[:4], samples=40, bezier=True)
    assert closed.ok.all() and bez.ok.all()
    assert np.array_equal(wavg.spline(surface, anchors[:5], samples=40, threads=1).xyz, c.xyz)


def test_correspond_identity(surface, anchors):
    m = wavg.correspond(surface, surface, anchors, anchors)
    assert isinstance(m, wavg.Correspondence)
    n = surface.vertex_count
    assert m.face.shape == (n,) and m.bary.shape == (n, 3) and m.xyz.shape == (n, 3)
    assert m.valid.dtype == np.bool_ and m.reason.shape == (n,)
    assert set(np.unique(m.reason)) <= {"valid", "unanswered", "no-round-trip",
                                        "negative-weight", "inconsistent"}
    assert np.array_equal(m.valid, m.reason == "valid")
    assert m.valid.mean() > 0.9
    # Onto itself the map is the identity where valid.
    err = np.linalg.norm(m.xyz[m.valid] - surface.vertices[m.valid], axis=1)
    assert err.max() < 1e-3
    assert m.report["source_vertices"] == n and m.report["anchors"] == len(anchors)
    assert m.report["reasons"]["valid"] == int(m.valid.sum())


def test_decal_anchor_uvs(surface, anchors):
    uv_in = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    uv, valid = wavg.decal(surface, anchors[:4], uv_in)
    assert uv.shape == (surface.vertex_count, 2) and valid.dtype == np.bool_
    assert np.isnan(uv[~valid]).all() and np.isfinite(uv[valid]).all()
    for a, want in zip(anchors[:4], uv_in):
        if valid[a]:
            assert np.allclose(uv[a], want, atol=1e-6)


def test_weight_limits_out_of_range_are_refused_with_the_range(surface, anchors):
    uv_in = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    for bad in (5.0, 0.1, float("nan")):
        with pytest.raises(ValueError, match="max_negative must be a finite weight of at most 0"):
            wavg.decal(surface, anchors[:4], uv_in, max_negative=bad)
        with pytest.raises(ValueError, match="at most 0"):
            wavg.correspond(surface, surface, anchors, anchors, max_negative=bad)
    with pytest.raises(ValueError, match="max_stretch must be a finite number above 1"):
        wavg.correspond(surface, surface, anchors, anchors, max_stretch=0.5)


def test_transfer_texture_onto_itself(surface, anchors):
    V, F = surface.vertices, surface.faces
    # A planar uv layout per face corner: the torus's own angles.
    ang = np.stack([np.arctan2(V[:, 1], V[:, 0]), np.arctan2(V[:, 2], np.hypot(V[:, 0], V[:, 1]) - 1)], -1)
    uv = (ang[F] / (2 * np.pi)) % 1.0
    S = wavg.Surface(V, F, uv=uv)
    S.precompute(landmarks=80, progress=False)
    tex = np.zeros((32, 32, 4), np.uint8)
    tex[..., 0] = np.arange(32)[None, :] * 8
    tex[..., 3] = 255
    out = wavg.transfer_texture(S, tex, S, anchors, anchors, size=(32, 32))
    assert out.shape == (32, 32, 4) and out.dtype == np.uint8
    assert (out[..., 3] > 0).mean() > 0.3


def test_remesher_runs_and_moves(surface):
    V = surface.vertices
    base_V = V[[0, 100, 200, 150]]
    base_F = [[0, 1, 2], [0, 2, 3]]
    r = wavg.Remesher(surface, base_V, base_F, levels=1, smooth=1)
    assert r.vertices is None
    try:
        v, f = r.run()
    except wavg.WavgError:
        pytest.skip("this base is refused by the remesher")
    assert v.shape[1] == 3 and np.array_equal(r.vertices, v)
    r.move_vertex(0, V[1])
    v2, _ = r.run()
    assert v2.shape == v.shape


def test_remesher_real_cage(data_dir):
    S = wavg.Surface.open(data_dir / "textured" / "spot" / "spot_triangulated.obj")
    S.precompute(landmarks=200, progress=False)
    bv, bf = wavg.read_mesh(data_dir / "meshes" / "spot_control_mesh.obj")
    r = wavg.Remesher(S, bv, bf, levels=1, smooth=1)
    v, f = r.run()
    assert f.shape[1] == 3 and len(v) > len(bv)
    assert r.report["vertices"] == len(v)


def test_render_and_png_round_trip(tmp_path, surface, anchors):
    c = wavg.spline(surface, anchors[:4], samples=30)
    img = wavg.render(surface, size=(64, 48), curves=[c], points=surface.vertices[anchors],
                      scalar=surface.vertices[:, 2])
    assert img.shape == (48, 64, 4) and img.dtype == np.uint8
    assert len(np.unique(img.reshape(-1, 4), axis=0)) > 10  # not a blank picture
    wavg.save_png(tmp_path / "a.png", img)
    assert np.array_equal(wavg.read_png(tmp_path / "a.png"), img)
    plain = wavg.render(surface, size=(64, 48), view=(90, 0))
    assert not np.array_equal(plain, img)


EXAMPLES = sorted((ROOT / "python" / "examples").glob("[a-z]*.py"))


def test_the_examples_are_found():
    # An empty list would skip every example silently.
    assert {e.name for e in EXAMPLES} >= {"correspond.py", "decal.py", "remesh.py", "render.py",
                                          "spline.py", "transfer_texture.py"}


@pytest.mark.parametrize("example", EXAMPLES, ids=[e.name for e in EXAMPLES])
def test_examples_run(example, tmp_path):
    r = subprocess.run([sys.executable, str(example), str(tmp_path)], capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, r.stderr


def test_wireframe_of_an_opened_quad_mesh_leaves_out_the_diagonals(tmp_path):
    # A torus of quads: opened from the file, the wireframe draws the quads' edges only;
    # the same triangles given as arrays draw every triangle edge.
    n, m = 24, 12
    u, v = np.meshgrid(np.arange(n) * 2 * np.pi / n, np.arange(m) * 2 * np.pi / m, indexing="ij")
    V = np.stack([(1 + 0.4 * np.cos(v)) * np.cos(u), (1 + 0.4 * np.cos(v)) * np.sin(u),
                  0.4 * np.sin(v)], axis=-1).reshape(-1, 3)
    idx = lambda i, j: (i % n) * m + (j % m) + 1  # noqa: E731
    quads = [(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1))
             for i in range(n) for j in range(m)]
    path = tmp_path / "quads.obj"
    path.write_text("".join(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in V)
                    + "".join("f %d %d %d %d\n" % q for q in quads))
    opened = wavg.Surface.open(path)
    assert opened.face_count == 2 * len(quads)
    arrays = wavg.Surface(opened.vertices, opened.faces)
    kw = dict(size=(160, 120), view=(30, 40))
    plain = wavg.render(arrays, **kw)
    assert np.array_equal(plain, wavg.render(opened, **kw))
    wire_q = np.any(wavg.render(opened, wireframe=True, **kw) != plain, axis=-1)
    wire_t = np.any(wavg.render(arrays, wireframe=True, **kw) != plain, axis=-1)
    assert wire_q.sum() > 200, wire_q.sum()  # the quads' edges are drawn
    assert wire_q.sum() < 0.85 * wire_t.sum(), (wire_q.sum(), wire_t.sum())
    assert (wire_q & ~wire_t).sum() < 0.02 * wire_q.sum()  # no edge the triangles lack
    # A pickled copy keeps the file's polygons.
    again = pickle.loads(pickle.dumps(opened))
    assert np.array_equal(wavg.render(again, wireframe=True, **kw),
                          wavg.render(opened, wireframe=True, **kw))


def test_png_errors_are_io_errors(tmp_path):
    (tmp_path / "not.png").write_text("hello")
    for bad in (tmp_path, tmp_path / "not.png"):
        with pytest.raises(wavg.WavgIOError):
            wavg.read_png(bad)
    with pytest.raises(wavg.WavgIOError, match="nodir"):
        wavg.save_png(tmp_path / "nodir" / "a.png", np.zeros((4, 4, 4), np.uint8))
