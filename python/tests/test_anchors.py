"""Anchors files from Python: `wavg.read_anchors` / `wavg.write_anchors` (the library's
`wavg::anchors`, the files `wavg anchors` writes) and `S.spread_anchors` against the CLI."""

import subprocess

import numpy as np
import pytest

import wavg
from conftest import write_obj


def test_vertex_ids_round_trip(tmp_path, surface):
    ids = np.array([0, 5, 17, surface.vertex_count - 1])
    path = tmp_path / "a.txt"
    wavg.write_anchors(path, ids)
    assert path.read_text() == "".join(f"v {v}\n" for v in ids)
    back = wavg.read_anchors(path, surface)
    assert isinstance(back, np.ndarray) and back.dtype == np.int64
    np.testing.assert_array_equal(back, ids)


def test_surface_points_round_trip_exactly(tmp_path, surface):
    faces = np.array([3, 40, 7])
    bary = np.array([[0.1, 0.2, 0.7], [1 / 3, 1 / 3, 1 / 3], [0.0, 0.25, 0.75]])
    path = tmp_path / "p.txt"
    wavg.write_anchors(str(path), (faces, bary))
    f, b = wavg.read_anchors(str(path), surface)
    np.testing.assert_array_equal(f, faces)
    np.testing.assert_array_equal(b, bary)  # shortest round-trip numbers: exact
    # The pair is what a Solver takes.
    assert wavg.Solver(surface, (f, b)).anchor_count == 3


def test_mixed_file_becomes_surface_points(tmp_path, surface):
    path = tmp_path / "m.txt"
    path.write_text("# a comment\nv 4\n\nf 2 0.5 0.25 0.25  # trailing\n")
    f, b = wavg.read_anchors(path, surface)
    vf, vb = surface.vertex_points([4])
    np.testing.assert_array_equal(f, [vf[0], 2])
    np.testing.assert_array_equal(b, [vb[0], [0.5, 0.25, 0.25]])


@pytest.mark.parametrize("text, line", [
    ("v 0\nv x\n", 2),
    ("v 0\nv 1\n\nv 100000\n", 4),
    ("f 0 0.5 0.5\n", 1),
    ("v 1\nf 999999 0.2 0.3 0.5\n", 2),
])
def test_bad_file_names_file_and_line(tmp_path, surface, text, line):
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(wavg.InvalidArgumentError) as e:
        wavg.read_anchors(path, surface)
    assert isinstance(e.value, ValueError)
    assert f"{path}:{line}" in str(e.value)


def test_empty_file_and_missing_file(tmp_path, surface):
    path = tmp_path / "empty.txt"
    path.write_text("# nothing\n\n")
    with pytest.raises(wavg.InvalidArgumentError, match="no anchors"):
        wavg.read_anchors(path, surface)
    with pytest.raises(FileNotFoundError):
        wavg.read_anchors(tmp_path / "absent.txt", surface)


def test_write_rejects_bad_anchors(tmp_path):
    path = tmp_path / "w.txt"
    with pytest.raises(ValueError, match="anchors"):
        wavg.write_anchors(path, [-1, 2])
    with pytest.raises(ValueError, match="anchors"):
        wavg.write_anchors(path, ([0], [[np.nan, 0.5, 0.5]]))
    with pytest.raises(TypeError, match="anchors"):
        wavg.write_anchors(path, [0.5, 1.5])
    # Only what `read_anchors` takes back is written.
    with pytest.raises(wavg.InvalidArgumentError, match="do not sum to 1"):
        wavg.write_anchors(path, ([0], [[5.0, 0.0, 1.0]]))
    with pytest.raises(wavg.InvalidArgumentError, match="anchor"):
        wavg.write_anchors(path, np.zeros(0, np.int64))
    assert not path.exists()


@pytest.mark.parametrize("k, seed", [(1, 0), (12, 0), (30, 7)])
def test_spread_anchors_equal_the_cli(tmp_path, cli, surface, torus_mesh, k, seed):
    mesh, emb, out = tmp_path / "t.obj", tmp_path / "t.wavg", tmp_path / "a.txt"
    write_obj(mesh, *torus_mesh)
    surface.save_embedding(emb)
    subprocess.run([cli, "anchors", "--mesh", str(mesh), "--embedding", str(emb), "--count", str(k),
                    "--seed", str(seed), "-o", str(out)], check=True, capture_output=True)
    ours = surface.spread_anchors(k, seed)
    np.testing.assert_array_equal(wavg.read_anchors(out, surface), ours)
    # and the file Python writes is the CLI's, byte for byte
    wavg.write_anchors(tmp_path / "py.txt", ours)
    assert (tmp_path / "py.txt").read_bytes() == out.read_bytes()
