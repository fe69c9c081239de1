"""wavg.batch in-process: fingerprints, atomic writes, the manifest, skipping and redoing,
failures, the command line. The Dask and process-pool runs are in test_batch_dask.py."""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest

import batch_fixtures as bf
import wavg
import wavg.batch as wb
from wavg.batch import __main__ as cli
from wavg.batch import jobs, store

LANDMARKS = 40


@pytest.fixture(scope="module")
def assets(tmp_path_factory: pytest.TempPathFactory) -> dict:
    return bf.make_assets(tmp_path_factory.mktemp("assets"))


def test_atomic_write_leaves_nothing_on_error(tmp_path: Path) -> None:
    target = tmp_path / "out.bin"
    target.write_bytes(b"old")

    def boom(f: object) -> None:
        f.write(b"partial")  # type: ignore[attr-defined]
        raise RuntimeError("disk on fire")

    with pytest.raises(RuntimeError):
        store.atomic_write(target, boom)
    assert target.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.bin"]


def test_check_detects_changed_inputs_and_corruption(tmp_path: Path) -> None:
    src = tmp_path / "in.txt"
    src.write_text("a")
    out = tmp_path / "out.bin"
    fp = store.fingerprint({"mesh": src}, {"landmarks": 10})
    store.atomic_write_bytes(out, b"result")
    store.record(out, fp, {"valid_fraction": 0.5}, "run-1")
    assert store.check(out, fp) == ({"valid_fraction": 0.5}, "run-1")
    assert store.fingerprint({"mesh": src}, {"landmarks": 11}) != fp
    src.write_text("b")
    assert store.fingerprint({"mesh": src}, {"landmarks": 10}) != fp
    out.write_bytes(b"resulT")  # same size, one byte changed
    assert store.check(out, fp) is None
    out.write_bytes(b"result")
    assert store.check(out, fp) is not None
    store.sidecar_path(out).write_text("{not json")
    assert store.check(out, fp) is None


def test_sweep_removes_only_temporaries(tmp_path: Path) -> None:
    (tmp_path / "a.wavg").write_bytes(b"x")
    (tmp_path / (".a.wavg" + store.TMP_MARK + "x1")).write_bytes(b"half")
    (tmp_path / ".hidden").write_bytes(b"y")
    assert store.sweep_temporaries(tmp_path) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == [".hidden", "a.wavg"]


def test_output_names_are_unique_and_stable() -> None:
    names = wb._names(["a/x.obj", "b/x.off.gz", "c/y.ply", "x.obj"], ".wavg")
    assert names == ["x.wavg", "x-2.wavg", "y.wavg", "x-3.wavg"]
    assert jobs.stem("d/m.obj.gz") == "m"


def test_read_anchors_formats(tmp_path: Path, assets: dict) -> None:
    s = wavg.Surface.open(assets["template"])
    p = tmp_path / "a.txt"
    p.write_text("# c\nv 3\n\nv 7 # end\n")
    assert jobs.read_anchors(p, s).tolist() == [3, 7]
    p.write_text("f 2 0.2 0.3 0.5\nv 7\n")
    faces, bary = jobs.read_anchors(p, s)
    vf, vb = s.vertex_points(np.array([7]))
    assert faces.tolist() == [2, int(np.asarray(vf)[0])]
    assert np.allclose(bary[0], [0.2, 0.3, 0.5]) and np.allclose(bary[1], np.asarray(vb)[0])
    p.write_text("v 1\nq 2\n")
    with pytest.raises(ValueError, match=r"a.txt:2"):
        jobs.read_anchors(p, s)


def test_precompute_in_process_skip_redo_and_failure(tmp_path: Path, assets: dict) -> None:
    meshes = assets["meshes"][:3] + [assets["invalid"], str(tmp_path / "missing.obj")]
    out = tmp_path / "emb"
    m = wb.precompute_all(meshes, out, landmarks=LANDMARKS)
    assert [j["input"] for j in m] == meshes
    assert [j["status"] for j in m] == ["done"] * 3 + ["failed"] * 2
    assert "InvalidMeshError" in m[3]["error"]
    assert "missing.obj" in m[4]["error"]
    on_disk = json.loads((out / "manifest.json").read_text())
    assert on_disk["jobs"] == json.loads(json.dumps(m.jobs))
    for j in m.jobs[:3]:
        s = wavg.Surface.open(j["input"], embedding=j["output"])
        assert s.embedding.shape == (s.vertex_count, 8)
        assert j["vertices"] == s.vertex_count and j["seconds"] > 0 and j["worker"]
    before = {j["output"]: Path(j["output"]).read_bytes() for j in m.jobs[:3]}

    again = wb.precompute_all(meshes, out, landmarks=LANDMARKS)
    assert [j["status"] for j in again] == ["skipped"] * 3 + ["failed"] * 2
    assert again[0]["vertices"] == m[0]["vertices"]  # figures repeated from the sidecar

    victim = Path(m[1]["output"])
    data = bytearray(victim.read_bytes())
    data[len(data) // 2] ^= 0xFF
    victim.write_bytes(bytes(data))
    third = wb.precompute_all(meshes, out, landmarks=LANDMARKS)
    assert [j["status"] for j in third][:3] == ["skipped", "done", "skipped"]
    assert {j["output"]: Path(j["output"]).read_bytes() for j in third.jobs[:3]} == before

    fourth = wb.precompute_all(meshes[:1], out, landmarks=LANDMARKS + 1)
    assert fourth[0]["status"] == "done"  # another option: another fingerprint
    assert wb.precompute_all(meshes[:1], out, landmarks=LANDMARKS + 1, overwrite=True)[0]["status"] == "done"
    assert not [p for p in out.iterdir() if store.TMP_MARK in p.name]


def test_an_attempt_lost_with_its_worker_counts_as_done(tmp_path: Path, assets: dict) -> None:
    job = jobs.Job("precompute", 0, assets["meshes"][0], str(tmp_path / "a.wavg"), {"mesh": assets["meshes"][0]}, {"landmarks": LANDMARKS, "seed": 0}, run="run-1")
    assert jobs.run_job(job)["status"] == "done"
    again = jobs.run_job(job)  # the same run resubmits a job whose result was lost
    assert again["status"] == "done" and again["figures"]["vertices"] > 0
    assert jobs.run_job(dataclasses.replace(job, run="run-2"))["status"] == "skipped"


def test_pair_arguments_are_checked(tmp_path: Path, assets: dict) -> None:
    with pytest.raises(TypeError, match=r"targets\[0\]"):
        wb.correspond_all(assets["template"], assets["template_anchors"], ["just-a-path.obj"], tmp_path)
    with pytest.raises(TypeError, match="executor"):
        wb.precompute_all(assets["meshes"][:1], tmp_path, executor=object())
    for one in (assets["meshes"][0], Path(assets["meshes"][0])):
        with pytest.raises(TypeError, match=r"meshes: expected a list of mesh paths, got one path"):
            wb.precompute_all(one, tmp_path / "one")
    assert not (tmp_path / "one").exists()


def test_options_are_checked_once_before_any_job(tmp_path: Path, assets: dict) -> None:
    meshes = assets["meshes"][:2]
    for bad, error, says in [
        ({"landmarks": -1}, ValueError, "landmarks must be an integer from 0 to 4294967295, got -1"),
        ({"landmarks": 2**32}, ValueError, "landmarks must be"),
        ({"landmarks": 12.5}, TypeError, "landmarks must be an integer, got 12.5"),
        ({"seed": -3}, ValueError, "seed must be an integer from 0"),
    ]:
        with pytest.raises(error, match=says):
            wb.precompute_all(meshes, tmp_path / "p", **bad)
    pair = (assets["template"], assets["texture"], assets["template_anchors"], assets["targets"][:2])
    with pytest.raises(ValueError, match="size"):
        wb.transfer_all(*pair, tmp_path / "t", size=(64, 0))
    with pytest.raises(ValueError, match="landmarks"):
        wb.transfer_all(*pair, tmp_path / "t", landmarks=-5)
    with pytest.raises(ValueError, match='validity must be "local" or "paper"'):
        wb.correspond_all(assets["template"], assets["template_anchors"], assets["targets"][:2], tmp_path / "c", validity="strict")
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    # NumPy integers are integers; 0 is the library's choice, as None.
    assert wb._landmarks(np.int64(40)) == 40 and wb._landmarks(0) is None


def test_builtin_meshes_are_inputs_too(tmp_path: Path) -> None:
    m = wb.precompute_all(["builtin:sphere-small"], tmp_path, landmarks=20)
    assert [j["status"] for j in m] == ["done"], [j["error"] for j in m]
    out = tmp_path / "sphere-small.wavg"
    assert m[0]["output"] == str(out) and out.is_file()
    s = wavg.Surface.open("builtin:sphere-small", embedding=out)
    assert s.has_embedding and len(s.landmarks) == 20
    assert [j["status"] for j in wb.precompute_all(["builtin:sphere-small"], tmp_path, landmarks=20)] == ["skipped"]


def test_template_failure_fails_every_job(tmp_path: Path, assets: dict) -> None:
    m = wb.correspond_all(assets["invalid"], assets["template_anchors"], assets["targets"][:2], tmp_path, landmarks=LANDMARKS)
    assert [j["status"] for j in m] == ["failed", "failed"]
    assert all(j["error"].startswith("template ") for j in m)


def test_command_line(tmp_path: Path, assets: dict, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "cli"
    status = cli.main(["precompute", *assets["meshes"][:2], "-o", str(out), "--landmarks", str(LANDMARKS)])
    captured = capsys.readouterr()
    assert status == 0
    assert captured.out.strip() == str(out / "manifest.json")
    assert "2/2 jobs, 0 failed" in captured.err
    lst = tmp_path / "targets.txt"
    lst.write_text("".join(f"{m} {a}\n" for m, a in assets["targets"][:2]))
    status = cli.main(
        ["correspond", "--template", assets["template"], "--template-anchors", assets["template_anchors"],
         "--targets", str(lst), "--target", assets["invalid"], assets["targets"][-1][1],
         "-o", str(tmp_path / "co"), "--landmarks", str(LANDMARKS)]
    )  # fmt: skip
    captured = capsys.readouterr()
    assert status == 1
    assert "3/3 jobs, 1 failed" in captured.err and "failed: " in captured.err
    m = wb.Manifest.load(captured.out.strip())
    assert [j["status"] for j in m] == ["failed", "done", "done"]  # --target first, then the list
    with np.load(m[1]["output"]) as z:
        assert set(z.files) >= {"face", "bary", "xyz", "valid"}
        n = wavg.Surface.open(assets["template"]).vertex_count
        assert z["face"].shape == (n,) and z["bary"].shape == (n, 3) and z["xyz"].shape == (n, 3)
    with pytest.raises(SystemExit):
        cli.main(["transfer", "--template", "t.obj", "--template-anchors", "a.txt", "--texture", "t.png", "-o", str(tmp_path), "--size", "0x3"])
    capsys.readouterr()


def test_command_line_without_dask(tmp_path: Path, assets: dict, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setitem(sys.modules, "distributed", None)  # `import distributed` fails
    for where in (["--local", "2"], ["--scheduler", "tcp://127.0.0.1:1"]):
        with pytest.raises(SystemExit) as e:
            cli.main(["precompute", assets["meshes"][0], "-o", str(tmp_path / "out"), *where])
        assert e.value.code == 2
        err = capsys.readouterr().err
        assert f"{where[0]} runs on Dask, which is not installed" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


class BreaksOnce(cf.Executor):
    """Runs jobs in the calling thread, except that the job at ``index`` comes back as if
    its worker process had died (``BrokenExecutor``), as a broken pool reports it."""

    def __init__(self, index: int):
        self.index = index

    def submit(self, fn, /, *args, **kwargs):  # type: ignore[no-untyped-def, override]
        fut: cf.Future = cf.Future()
        if args[0].index == self.index:
            fut.set_exception(cf.BrokenExecutor("a process of the pool died"))
        else:
            fut.set_result(fn(*args, **kwargs))
        return fut


def test_other_executors(tmp_path: Path, assets: dict) -> None:
    meshes = assets["meshes"][:4]
    ref = wb.precompute_all(meshes, tmp_path / "ref", landmarks=LANDMARKS)
    with cf.ThreadPoolExecutor(2) as pool:
        m = wb.precompute_all(meshes, tmp_path / "threads", pool, landmarks=LANDMARKS)
    assert [j["status"] for j in m] == ["done"] * 4
    for a, b in zip(m, ref):
        assert Path(a["output"]).read_bytes() == Path(b["output"]).read_bytes()
    # An executor that cannot be replaced: the lost job fails with why, the others finish.
    m = wb.precompute_all(meshes, tmp_path / "flaky", BreaksOnce(1), landmarks=LANDMARKS)
    assert [j["status"] for j in m] == ["done", "failed", "done", "done"]
    assert m[1]["error"].startswith("worker lost 1 times") and "BrokenExecutor" in m[1]["error"]
    assert not (tmp_path / "flaky" / Path(m[1]["output"]).name).exists()


def test_driver_killed_mid_run_then_rerun(tmp_path: Path, assets: dict) -> None:
    import signal
    import subprocess
    import sys
    import time

    meshes = [m for m in assets["meshes"] if m != assets["invalid"]]
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "wavg.batch", "precompute", *meshes, "-o", str(out), "--landmarks", str(LANDMARKS), "--threads", "1"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if out.is_dir() and any(p.name.endswith(store.SIDECAR) for p in out.iterdir()):
            break
        time.sleep(0.005)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    finished = {p.name[: -len(store.SIDECAR)] for p in out.iterdir() if p.name.endswith(store.SIDECAR)}
    assert finished, "the driver finished nothing before it was killed"
    m = wb.precompute_all(meshes, out, landmarks=LANDMARKS)
    statuses = {Path(j["output"]).name: j["status"] for j in m}
    assert all(statuses[n] == "skipped" for n in finished)
    assert set(statuses.values()) == {"skipped", "done"}  # killed mid-run: some left to do
    assert not [p for p in out.iterdir() if store.TMP_MARK in p.name]
    ref = wb.precompute_all(meshes, tmp_path / "ref", landmarks=LANDMARKS)
    for a, b in zip(m, ref):
        assert Path(a["output"]).read_bytes() == Path(b["output"]).read_bytes()


def test_outputs_have_ordinary_permissions(tmp_path: Path) -> None:
    out = tmp_path / "o.bin"
    store.atomic_write_bytes(out, b"x")
    old = os.umask(0o022)
    os.umask(old)
    assert out.stat().st_mode & 0o777 == 0o666 & ~old


@pytest.fixture()
def wavg_bin(cli: str) -> str:
    """The `wavg` command line (the conftest's `cli`; this module's `cli` is wavg.batch's)."""
    return cli


def test_precompute_goes_through_the_shared_cache(tmp_path: Path, assets: dict, wavg_bin: str, monkeypatch: pytest.MonkeyPatch) -> None:
    import subprocess

    cache = tmp_path / "cache"
    monkeypatch.setenv("WAVG_CACHE_DIR", str(cache))
    meshes = [m for m in assets["meshes"] if m != assets["invalid"]][:2]
    m = wb.precompute_all(meshes, tmp_path / "out", landmarks=LANDMARKS)
    assert m.ok
    # `wavg cache list` shows the entries the batch wrote.
    listed = json.loads(subprocess.run([wavg_bin, "cache", "list", "--json"], check=True, capture_output=True, text=True).stdout)
    assert [e["writer"] for e in listed["entries"]] == ["python", "python"]
    assert [e["landmarks"] for e in listed["entries"]] == [LANDMARKS, LANDMARKS]
    # Each output is the cache entry's embedding, found under the shared key.
    for mesh, job in zip(meshes, m):
        s = wavg.Surface.open(mesh)
        assert s.load_cached(landmarks=LANDMARKS)
        out = wavg.Surface.open(mesh, embedding=job["output"])
        assert np.array_equal(s.embedding, out.embedding)
    # Without `landmarks`, the library's choice: the key of `precompute()` without options.
    d = wb.precompute_all(meshes[:1], tmp_path / "default")
    assert d.ok and d.options["landmarks"] is None
    s = wavg.Surface.open(meshes[0])
    assert s.load_cached()
    assert np.array_equal(s.embedding, wavg.Surface.open(meshes[0], embedding=d.jobs[0]["output"]).embedding)
    assert len(wavg.cache_entries()) == 3
