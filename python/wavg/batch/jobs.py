"""The jobs a worker runs: precompute, correspond and transfer one asset.

A :class:`Job` carries file paths and small options only, so it pickles to a few hundred
bytes whatever the meshes weigh; the worker reads its inputs itself. :func:`run_job` is the
one entry point (a top-level function, so every executor can pickle it): it fingerprints
the inputs, skips an intact output made from the same inputs, otherwise computes, writes
the output atomically and records its fingerprint, and returns a small result dict. Errors
of the job (a bad mesh, a missing file) come back as ``status="failed"`` with the message;
only the death of the worker itself escapes, for the executor layer to retry.
"""

from __future__ import annotations

import inspect
import io
import os
import socket
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from . import store

#: Suffixes stripped from a mesh file name to name its outputs.
MESH_SUFFIXES = (".gz", ".obj", ".off", ".ply")


@dataclass(frozen=True)
class Job:
    """One unit of work: ``kind`` (``precompute``, ``correspond`` or ``transfer``), the
    input it is listed under in the manifest, the output file, the input files (by role)
    and the options that make its fingerprint, and the threads it may use (not part of the
    fingerprint: results do not depend on it). ``run`` names the batch call that dispatched
    the job: an output recorded by the same run was made by an earlier attempt whose result
    was lost with its worker, so it counts as ``done``, not ``skipped``."""

    kind: str
    index: int
    input: str
    output: str
    files: Mapping[str, str | None] = field(default_factory=dict)
    options: Mapping[str, Any] = field(default_factory=dict)
    overwrite: bool = False
    threads: int | None = 1
    run: str = ""


def stem(path: str | os.PathLike[str]) -> str:
    """A mesh file's name without its mesh and compression suffixes (``a/b.obj.gz`` -> ``b``;
    ``builtin:torus`` -> ``torus``)."""
    name = Path(path).name.removeprefix("builtin:")
    changed = True
    while changed:
        changed = False
        for suffix in MESH_SUFFIXES:
            if name.lower().endswith(suffix) and len(name) > len(suffix):
                name = name[: -len(suffix)]
                changed = True
    return name


def worker_name() -> str:
    """The Dask worker's address inside a Dask worker, else ``host:pid``."""
    if "distributed" in sys.modules:
        try:
            from distributed import get_worker

            return str(get_worker().address)
        except (ValueError, ImportError, AttributeError):
            pass
    return f"{socket.gethostname()}:{os.getpid()}"


def run_job(job: Job) -> dict[str, Any]:
    """Runs ``job`` (or skips it) and returns ``status``, ``seconds``, ``worker``,
    ``error`` and the job's figures."""
    t0, c0 = time.perf_counter(), time.process_time()
    worker = worker_name()
    try:
        inputs = store.fingerprint(job.files, job.options)
        if not job.overwrite:
            found = store.check(job.output, inputs)
            if found is not None:
                figures, run = found
                status = "done" if job.run and run == job.run else "skipped"
                return _result(status, t0, c0, worker, None, figures)
        figures = RUNNERS[job.kind](job)
        store.record(job.output, inputs, figures, job.run)
        return _result("done", t0, c0, worker, None, figures)
    except Exception as e:  # a job's failure is data for the manifest, not a crash
        message = str(e) or repr(e)
        return _result("failed", t0, c0, worker, f"{type(e).__name__}: {message}", {})


def _result(status: str, t0: float, c0: float, worker: str, error: str | None, figures: Mapping[str, Any]) -> dict[str, Any]:
    """A job's result; ``cpu_seconds`` is the worker process's CPU time over the job (all
    its threads), a figure that does not depend on how busy the machine is."""
    return {
        "status": status,
        "seconds": round(time.perf_counter() - t0, 6),
        "cpu_seconds": round(time.process_time() - c0, 6),
        "worker": worker,
        "error": error,
        "figures": dict(figures),
    }


def _threads_kw(fn: Callable[..., Any], threads: int | None) -> dict[str, Any]:
    """``{"threads": threads}`` when ``fn`` takes that argument."""
    try:
        params = inspect.signature(fn).parameters
    except (TypeError, ValueError):
        return {}
    return {"threads": threads} if "threads" in params else {}


def open_surface(mesh: str, embedding: str | None, options: Mapping[str, Any], threads: int | None) -> Any:
    """The surface of ``mesh`` with ``embedding`` loaded, else its embedding from the
    embedding cache every way into wavg shares, else precomputed (and stored there)."""
    import wavg

    if embedding is not None:
        return wavg.Surface.open(mesh, embedding=embedding)
    s = wavg.Surface.open(mesh)
    landmarks, seed = _landmarks(options), int(options.get("seed", 0))
    if not s.load_cached(landmarks=landmarks, seed=seed):
        s.precompute(landmarks=landmarks, seed=seed, threads=threads, progress=False)
    return s


def read_anchors(path: str | os.PathLike[str], surface: Any) -> Any:
    """An anchors file as the Solver takes it (:func:`wavg.read_anchors`: vertex ids
    ``(k,)`` when every line is a vertex, else ``(faces (k,), bary (k, 3))``)."""
    import wavg

    return wavg.read_anchors(path, surface)


def _landmarks(options: Mapping[str, Any]) -> int | None:
    """The ``landmarks`` option: None (or absent) for the library's choice."""
    value = options.get("landmarks")
    return None if value is None else int(value)


def precompute(job: Job) -> dict[str, Any]:
    """Precomputes the embedding of ``job.files["mesh"]`` (or takes it from the embedding
    cache, where the precomputation also stores it) and writes the ``.wavg`` file."""
    import wavg

    o = job.options
    s = wavg.Surface.open(job.files["mesh"])
    t0 = time.perf_counter()
    s.precompute(landmarks=_landmarks(o), seed=int(o.get("seed", 0)), threads=job.threads, progress=False)
    seconds = time.perf_counter() - t0
    tmp = store.temporary_path(job.output)
    try:
        s.save_embedding(str(tmp))
        store.commit(tmp, job.output)
    finally:
        if tmp.exists():
            tmp.unlink()
    return {
        "vertices": int(s.vertex_count),
        "faces": int(s.face_count),
        "landmarks": int(len(s.landmarks)),
        "precompute_seconds": round(seconds, 6),
    }


def _pair(job: Job) -> tuple[Any, Any, Any, Any]:
    """Template and target surfaces with their anchors, checked to pair up."""
    f, o = job.files, job.options
    src = open_surface(f["template"], f.get("template_embedding"), o, job.threads)
    dst = open_surface(f["mesh"], f.get("embedding"), o, job.threads)
    a_src = read_anchors(f["template_anchors"], src)
    a_dst = read_anchors(f["anchors"], dst)
    k_src = len(a_src) if isinstance(a_src, np.ndarray) else len(a_src[0])
    k_dst = len(a_dst) if isinstance(a_dst, np.ndarray) else len(a_dst[0])
    if k_src != k_dst:
        raise ValueError(f"{f['anchors']}: {k_dst} anchors, the template has {k_src} ({f['template_anchors']})")
    return src, dst, a_src, a_dst


def correspond(job: Job) -> dict[str, Any]:
    """Maps every template vertex onto the target; writes ``face``, ``bary``, ``xyz``,
    ``valid`` (and ``reason``) to an ``.npz``."""
    import wavg

    src, dst, a_src, a_dst = _pair(job)
    t0 = time.perf_counter()
    kw = _threads_kw(wavg.correspond, job.threads)
    c = wavg.correspond(src, dst, a_src, a_dst, validity=job.options.get("validity", "local"), **kw)
    seconds = time.perf_counter() - t0
    arrays = {
        "face": np.asarray(c.face),
        "bary": np.asarray(c.bary),
        "xyz": np.asarray(c.xyz),
        "valid": np.asarray(c.valid),
        "reason": np.asarray(c.reason).astype(str),  # fixed-width text: loads without pickle
    }
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    store.atomic_write_bytes(job.output, buf.getvalue())
    n = int(arrays["valid"].shape[0])
    report = dict(getattr(c, "report", {}) or {})
    valid_fraction = report.get("valid_fraction", float(arrays["valid"].mean()) if n else 0.0)
    return {
        "vertices": n,
        "valid_fraction": float(valid_fraction),
        "map_seconds": round(seconds, 6),
        "vertices_per_s": round(n / seconds, 1) if seconds > 0 else None,
    }


def transfer(job: Job) -> dict[str, Any]:
    """Carries the template's texture onto the target's UV atlas; writes an RGBA PNG."""
    import wavg

    src, dst, a_src, a_dst = _pair(job)
    o = job.options
    t0 = time.perf_counter()
    size = o.get("size")
    if size is not None:
        size = (int(size), int(size)) if np.ndim(size) == 0 else (int(size[0]), int(size[1]))
    kw = _threads_kw(wavg.transfer_texture, job.threads)
    image = np.asarray(wavg.transfer_texture(src, job.files["template_texture"], dst, a_src, a_dst, size=size, **kw))
    seconds = time.perf_counter() - t0
    tmp = store.temporary_path(job.output)
    try:
        wavg.save_png(str(tmp), image)
        store.commit(tmp, job.output)
    finally:
        if tmp.exists():
            tmp.unlink()
    h, w = image.shape[:2]
    opaque = int(np.count_nonzero(image[..., 3])) if image.ndim == 3 and image.shape[2] == 4 else h * w
    return {
        "width": int(w),
        "height": int(h),
        "valid_texels": opaque,
        "valid_fraction": opaque / (h * w) if h * w else 0.0,
        "transfer_seconds": round(seconds, 6),
        "texels_per_s": round(opaque / seconds, 1) if seconds > 0 else None,
    }


#: What each job kind runs.
RUNNERS: dict[str, Callable[[Job], dict[str, Any]]] = {
    "precompute": precompute,
    "correspond": correspond,
    "transfer": transfer,
}
