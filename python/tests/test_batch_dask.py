"""wavg.batch on a real Dask LocalCluster (2 single-thread worker processes) and on a
ProcessPoolExecutor: outputs equal a serial in-process run, the invalid mesh fails alone,
a worker killed mid-run (SIGKILL) still ends with every job done and no partial file, a
rerun skips everything, a corrupted output is redone."""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os
import signal
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest

import batch_fixtures as bf
import wavg
import wavg.batch as wb
from wavg.batch import store

distributed = pytest.importorskip("distributed")

LANDMARKS = 40


@pytest.fixture(scope="module")
def assets(tmp_path_factory: pytest.TempPathFactory) -> dict:
    return bf.make_assets(tmp_path_factory.mktemp("assets"))


@pytest.fixture(scope="module")
def serial(assets: dict, tmp_path_factory: pytest.TempPathFactory) -> dict[str, wb.Manifest]:
    """The reference: every kind of job run in-process, one after the other."""
    root = tmp_path_factory.mktemp("serial")
    emb = wb.precompute_all(assets["meshes"], root / "emb", landmarks=LANDMARKS)
    return {
        "precompute": emb,
        "transfer": wb.transfer_all(
            assets["template"], assets["texture"], assets["template_anchors"], assets["targets"], root / "tr", embeddings=emb, size=48
        ),
        "correspond": wb.correspond_all(assets["template"], assets["template_anchors"], assets["targets"], root / "co", embeddings=emb),
    }


@pytest.fixture(scope="module")
def client() -> Any:
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def assert_same_outputs(kind: str, got: wb.Manifest, want: wb.Manifest) -> None:
    """Same inputs, statuses and output contents as the serial run."""
    assert [j["input"] for j in got] == [j["input"] for j in want]
    assert [j["status"] in ("done", "skipped") for j in got] == [j["status"] in ("done", "skipped") for j in want]
    for g, w in zip(got, want):
        if w["status"] == "failed":
            assert g["status"] == "failed" and g["error"] == w["error"]
            continue
        if kind == "precompute":
            a = wavg.Surface.open(g["input"], embedding=g["output"])
            b = wavg.Surface.open(w["input"], embedding=w["output"])
            assert np.array_equal(a.embedding, b.embedding), g["input"]
        elif kind == "transfer":
            assert Path(g["output"]).read_bytes() == Path(w["output"]).read_bytes(), g["input"]
        else:
            with np.load(g["output"]) as a, np.load(w["output"]) as b:
                for name in ("face", "bary", "xyz", "valid"):
                    assert np.array_equal(a[name], b[name], equal_nan=name != "valid"), (g["input"], name)


def no_partial_files(folder: Path) -> None:
    left = [p.name for p in folder.rglob("*") if store.TMP_MARK in p.name]
    assert left == [], left


def test_serial_reference_is_sound(serial: dict[str, wb.Manifest], assets: dict) -> None:
    for kind, m in serial.items():
        failed = [j["input"] for j in m if j["status"] == "failed"]
        assert failed == [assets["invalid"]], (kind, failed)
        assert "InvalidMeshError" in m.failed[0]["error"]
    assert len(serial["transfer"]) >= 8
    for j in serial["transfer"]:
        if j["status"] == "done":
            assert 0 < j["valid_fraction"] <= 1 and j["texels_per_s"] > 0
    for j in serial["correspond"]:
        if j["status"] == "done":
            assert j["valid_fraction"] > 0.5, j


def test_dask_runs_equal_serial_and_rerun_skips(client: Any, serial: dict, assets: dict, tmp_path: Path) -> None:
    emb = wb.precompute_all(assets["meshes"], tmp_path / "emb", client, landmarks=LANDMARKS)
    assert_same_outputs("precompute", emb, serial["precompute"])
    workers = {j["worker"] for j in emb if j["status"] == "done"}
    assert workers <= set(client.scheduler_info()["workers"]) and len(workers) == 2
    tr = wb.transfer_all(
        assets["template"], assets["texture"], assets["template_anchors"], assets["targets"], tmp_path / "tr", client, embeddings=emb, size=48
    )
    assert_same_outputs("transfer", tr, serial["transfer"])
    co = wb.correspond_all(assets["template"], assets["template_anchors"], assets["targets"], tmp_path / "co", client, embeddings=tmp_path / "emb")
    assert_same_outputs("correspond", co, serial["correspond"])

    again = wb.precompute_all(assets["meshes"], tmp_path / "emb", client, landmarks=LANDMARKS)
    assert [j["status"] for j in again] == ["failed" if j["status"] == "failed" else "skipped" for j in emb]
    again = wb.transfer_all(
        assets["template"], assets["texture"], assets["template_anchors"], assets["targets"], tmp_path / "tr", client, embeddings=emb, size=48
    )
    assert again.counts["done"] == 0 and again.counts["skipped"] == len(assets["targets"]) - 1

    victim = Path(tr[2]["output"])
    victim.write_bytes(victim.read_bytes()[:-10])  # truncated, as by a crash elsewhere
    redo = wb.transfer_all(
        assets["template"], assets["texture"], assets["template_anchors"], assets["targets"], tmp_path / "tr", client, embeddings=emb, size=48
    )
    assert [j["status"] for j in redo][:4] == ["skipped", "skipped", "done", "skipped"]
    assert_same_outputs("transfer", redo, serial["transfer"])
    for d in ("emb", "tr", "co"):
        no_partial_files(tmp_path / d)


def killer(pids: Callable[[], list[int]]) -> tuple[Callable[[int, int, int], None], list[int]]:
    """A progress callback that SIGKILLs one busy worker process after the first job ends."""
    killed: list[int] = []

    def progress(finished: int, total: int, failed: int) -> None:
        if finished == 1 and not killed:
            victims = pids()
            if victims:
                os.kill(victims[0], signal.SIGKILL)
                killed.append(victims[0])

    return progress, killed


def test_dask_worker_killed_mid_run(client: Any, serial: dict, assets: dict, tmp_path: Path) -> None:
    def busy_pids() -> list[int]:
        pids = client.run(os.getpid)
        return [pids[w] for w, keys in client.processing().items() if keys and w in pids]

    progress, killed = killer(busy_pids)
    valid = [m for m in assets["meshes"] if m != assets["invalid"]]
    m = wb.precompute_all(valid, tmp_path, client, landmarks=LANDMARKS, progress=progress)
    assert killed, "no worker was busy to be killed"
    assert [j["status"] for j in m] == ["done"] * len(valid)
    no_partial_files(tmp_path)
    want = wb.Manifest("precompute", [j for j in serial["precompute"] if j["input"] != assets["invalid"]])
    assert_same_outputs("precompute", m, want)
    client.wait_for_workers(2, timeout=60)


def test_process_pool_equals_serial_and_survives_a_kill(serial: dict, assets: dict, tmp_path: Path) -> None:
    ctx = multiprocessing.get_context("spawn")
    with cf.ProcessPoolExecutor(2, mp_context=ctx) as pool:
        emb = wb.precompute_all(assets["meshes"], tmp_path / "emb", pool, landmarks=LANDMARKS)
        assert_same_outputs("precompute", emb, serial["precompute"])
        co = wb.correspond_all(assets["template"], assets["template_anchors"], assets["targets"], tmp_path / "co", pool, embeddings=emb)
        assert_same_outputs("correspond", co, serial["correspond"])

        progress, killed = killer(lambda: list(getattr(pool, "_processes", {}) or {}))
        tr = wb.transfer_all(
            assets["template"], assets["texture"], assets["template_anchors"], assets["targets"], tmp_path / "tr", pool,
            embeddings=emb, size=48, progress=progress,
        )  # fmt: skip
    assert killed
    assert_same_outputs("transfer", tr, serial["transfer"])
    assert max(j["attempts"] for j in tr) >= 2  # the broken pool was replaced and jobs resubmitted
    for d in ("emb", "co", "tr"):
        no_partial_files(tmp_path / d)


def test_command_line_local_cluster(assets: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from wavg.batch import __main__ as cli

    meshes = assets["meshes"][:3]
    status = cli.main(["precompute", *meshes, "-o", str(tmp_path), "--local", "2", "--landmarks", str(LANDMARKS)])
    out = capsys.readouterr().out.strip()
    assert status == 0 and out == str(tmp_path / "manifest.json")
    m = wb.Manifest.load(out)
    assert [j["status"] for j in m] == ["done"] * 3
    assert all(j["worker"].startswith("tcp://") for j in m)
