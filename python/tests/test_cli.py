"""Equal to the CLI (the Rust API behind it) on the same inputs, bit for bit where the
code path is the same: the embedding file, forward and inverse problems, correspondence."""

import json
import subprocess

import numpy as np
import pytest

import wavg
from conftest import random_weights, write_obj


@pytest.fixture(scope="module")
def files(tmp_path_factory, torus_mesh, cli):
    d = tmp_path_factory.mktemp("cli")
    write_obj(d / "t.obj", *torus_mesh)
    subprocess.run([cli, "precompute", "--landmarks", "80", "-o", str(d / "t.wavg"),
                    str(d / "t.obj")], check=True, capture_output=True)
    return d


def _anchor_file(path, anchors):
    path.write_text("".join(f"v {a}\n" for a in anchors))


def test_precompute_file_identical(files, torus_mesh):
    S = wavg.Surface(*torus_mesh)
    S.precompute(landmarks=80, progress=False)
    S.save_embedding(files / "py.wavg")
    assert (files / "py.wavg").read_bytes() == (files / "t.wavg").read_bytes()


def test_forward_and_inverse_equal_cli(files, cli, torus_mesh, anchors):
    S = wavg.Surface.open(files / "t.obj", embedding=files / "t.wavg")
    sol = wavg.Solver(S, anchors)
    W = random_weights(np.random.default_rng(11), 300, len(anchors))
    _anchor_file(files / "a.txt", anchors)
    (files / "w.txt").write_text("".join(" ".join(repr(float(x)) for x in row) + "\n" for row in W))
    common = ["--mesh", str(files / "t.obj"), "--embedding", str(files / "t.wavg"),
              "--anchors", str(files / "a.txt")]
    subprocess.run([cli, "forward", *common, "--weights", str(files / "w.txt"),
                    "-o", str(files / "p.txt")], check=True, capture_output=True)
    rows = [line.split() for line in (files / "p.txt").read_text().splitlines()]
    P = sol.forward(W)
    cli_face = np.array([int(r[0]) for r in rows])
    cli_num = np.array([[float(x) for x in r[1:7]] for r in rows])
    assert np.array_equal(cli_face, P.face)
    assert np.array_equal(cli_num[:, :3], P.bary) and np.array_equal(cli_num[:, 3:], P.xyz)
    (files / "q.txt").write_text("".join(
        "f {} {} {} {}\n".format(f, *map(repr, map(float, b))) for f, b in zip(P.face, P.bary)))
    for verified in (False, True):
        extra = ["--verified"] if verified else []
        subprocess.run([cli, "inverse", *common, "--points", str(files / "q.txt"), *extra,
                        "-o", str(files / "iw.txt")], check=True, capture_output=True)
        cli_w = np.array([[float(x) for x in line.split()]
                          for line in (files / "iw.txt").read_text().splitlines()])
        # The CLI renormalises barycentrics it reads (their sum to 1): the same here.
        b = np.maximum(P.bary, 0.0)
        Wpy, ok = sol.inverse(P.face, b / b.sum(axis=1, keepdims=True), verified=verified)
        assert np.array_equal(cli_w, Wpy), f"verified={verified}"


def test_verified_inverse_without_weights_as_the_cli(files, cli, surface):
    # Where the CLI prints `none not-reached`, the package gives a NaN row and ok False.
    three = surface.spread_anchors(3, seed=0)
    S = wavg.Surface.open(files / "t.obj", embedding=files / "t.wavg")
    faces, bary = S.vertex_points(np.arange(S.vertex_count))
    _anchor_file(files / "a3.txt", three)
    (files / "v.txt").write_text("".join(f"v {i}\n" for i in range(S.vertex_count)))
    subprocess.run([cli, "inverse", "--mesh", str(files / "t.obj"), "--embedding",
                    str(files / "t.wavg"), "--anchors", str(files / "a3.txt"), "--points",
                    str(files / "v.txt"), "--verified", "-o", str(files / "iw3.txt")],
                   check=True, capture_output=True)
    lines = (files / "iw3.txt").read_text().splitlines()
    W, ok = wavg.Solver(S, three).inverse(faces, bary)
    none = np.array([line.startswith("none") for line in lines])
    assert none.any() and np.array_equal(none, ~ok)
    assert np.isnan(W[none]).all()
    cli_w = np.array([[float(x) for x in line.split()] for line in lines if not line.startswith("none")])
    assert np.array_equal(cli_w, W[ok])


def test_correspond_report_keys_and_map_equal_cli(files, cli, anchors):
    S = wavg.Surface.open(files / "t.obj", embedding=files / "t.wavg")
    _anchor_file(files / "a.txt", anchors)
    r = subprocess.run([cli, "correspond", "--source", str(files / "t.obj"),
                        "--target", str(files / "t.obj"), "--source-anchors", str(files / "a.txt"),
                        "--target-anchors", str(files / "a.txt"),
                        "--source-embedding", str(files / "t.wavg"),
                        "--target-embedding", str(files / "t.wavg"),
                        "-o", str(files / "map.txt"), "--json"],
                       check=True, capture_output=True, text=True)
    cli_report = json.loads(r.stdout)
    m = wavg.correspond(S, S, anchors, anchors)
    assert set(m.report) == set(cli_report)
    for key in ("source_vertices", "valid", "valid_fraction", "reasons", "flipped_faces", "stretch"):
        assert m.report[key] == cli_report[key], key
    lines = (files / "map.txt").read_text().splitlines()
    for i, line in enumerate(lines):
        parts = line.split()
        if parts[0] == "none":
            assert not m.valid[i] and m.reason[i] == parts[1]
        else:
            assert m.valid[i] and int(parts[0]) == m.face[i]
            assert np.array_equal([float(x) for x in parts[4:7]], m.xyz[i])
