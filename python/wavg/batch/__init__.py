"""Many assets at once: precompute, transfer textures and correspond over a whole library
on a Dask cluster, any ``concurrent.futures.Executor`` or in-process.

Every function takes file paths, writes one output per input into ``out_dir`` (atomically,
with a fingerprint of its inputs beside it), skips inputs whose intact output was made from
the same inputs, and returns a :class:`Manifest` (also written as ``out_dir/manifest.json``)
with one entry per input, in input order. ``executor`` is a ``dask.distributed.Client``, a
``concurrent.futures.Executor`` (a process pool, Ray's) or ``None`` for in-process. Jobs
carry paths, never arrays. ``threads`` is the threads per job: by default 1 on an executor
(so that N worker processes use N cores) and all cores in-process. Dask is imported only
when a Client is passed.
"""

from __future__ import annotations

import operator
import os
import time
from pathlib import Path
from typing import Any, Sequence, Union

import numpy as np

from . import store
from .executors import Progress, run_all
from .jobs import Job, stem
from .manifest import Manifest

__all__ = ["precompute_all", "transfer_all", "correspond_all", "Manifest"]

PathLike = Union[str, "os.PathLike[str]"]


def _abs(p: PathLike) -> str:
    """A file's absolute path; a builtin mesh's name (``builtin:torus``) as it is."""
    name = os.fspath(p)
    if isinstance(name, str) and name.startswith(store.BUILTIN_PREFIX):
        return name
    return os.path.abspath(name)


def _names(inputs: Sequence[PathLike], suffix: str) -> list[str]:
    """Output file names: the input's stem and ``suffix``; a stem met again gets ``-2``,
    ``-3``... in input order, so that no two inputs share an output."""
    seen: set[str] = set()
    out = []
    for p in inputs:
        base = stem(p) or "mesh"
        name, n = base + suffix, 1
        while name in seen:
            n += 1
            name = f"{base}-{n}{suffix}"
        seen.add(name)
        out.append(name)
    return out


def _threads(threads: int | None, executor: Any) -> int | None:
    """Threads per job: as given, else 1 on an executor and all cores (``None``) in-process."""
    if threads is not None:
        if int(threads) < 1:
            raise ValueError(f"threads: expected a positive number or None, got {threads!r}")
        return int(threads)
    return None if executor is None else 1


def _run(
    kind: str,
    jobs: list[Job],
    out_dir: Path,
    executor: Any,
    progress: Progress | None,
    options: dict[str, Any],
    extra: list[dict[str, Any]] | None = None,
) -> Manifest:
    """Runs ``jobs``, clears what killed jobs left, writes and returns the manifest."""
    t0 = time.perf_counter()
    out_dir.mkdir(parents=True, exist_ok=True)
    store.sweep_temporaries(out_dir)
    results = run_all(jobs, executor, progress)
    store.sweep_temporaries(out_dir)
    entries = []
    for job, r, more in zip(jobs, results, extra or [{}] * len(jobs)):
        entry = {
            "input": job.input,
            "output": job.output,
            "status": r["status"],
            "seconds": r["seconds"],
            "cpu_seconds": r.get("cpu_seconds"),
            "worker": r["worker"],
            "error": r["error"],
            "attempts": r.get("attempts", 1),
        }
        entry.update(more)
        entry.update(r["figures"])
        entries.append(entry)
    m = Manifest(kind, entries, round(time.perf_counter() - t0, 6), options, version=store.package_version())
    m.write(out_dir / "manifest.json")
    return m


def _whole(name: str, value: Any, lo: int, hi: int) -> int:
    """An integer option checked once, before any job (the message ``S.precompute`` gives):
    ``TypeError`` for a non-integer, ``ValueError`` outside ``lo..=hi``."""
    try:
        n = operator.index(value)
    except TypeError:
        raise TypeError(f"{name} must be an integer, got {value!r}") from None
    if not lo <= n <= hi:
        raise ValueError(f"{name} must be an integer from {lo} to {hi}, got {value!r}")
    return n


def _landmarks(landmarks: int | None) -> int | None:
    """The ``landmarks`` option: None (or 0) for the library's choice, else a number of
    landmarks (checked here, so a bad value fails the call, not every job)."""
    n = None if landmarks is None else _whole("landmarks", landmarks, 0, 2**32 - 1)
    return n or None


def _size(size: Any) -> Any:
    """The ``size`` option of :func:`transfer_all`: None, ``W`` or ``(W, H)``, positive."""
    if size is None:
        return None
    sides = [size] if np.ndim(size) == 0 else list(size)
    if len(sides) not in (1, 2):
        raise ValueError(f"size: expected W or (W, H), got {size!r}")
    for i, side in enumerate(sides):
        _whole(f"size[{i}]" if len(sides) == 2 else "size", side, 1, 2**32 - 1)
    return size


def precompute_all(
    meshes: Sequence[PathLike],
    out_dir: PathLike,
    executor: Any = None,
    landmarks: int | None = None,
    overwrite: bool = False,
    *,
    seed: int = 0,
    threads: int | None = None,
    progress: Progress | None = None,
) -> Manifest:
    """Precomputes the embedding of every mesh into ``out_dir/NAME.wavg`` (``NAME``: the
    mesh file's name without ``.obj``/``.off``/``.ply``/``.gz``).

    ``landmarks``: None (the default) for the library's choice, the one every way into
    wavg makes (``wavg precompute`` without options). Embeddings go through the embedding
    cache every way into wavg shares (``wavg cache list`` lists them, writer ``python``):
    a mesh already precomputed with these options, by any door, is read from there.
    ``overwrite=True`` recomputes outputs that are up to date. ``progress(finished,
    total, failed)`` is called after each job. A mesh that cannot be embedded (invalid,
    missing) ends ``failed`` with its message; the others go on.
    """
    if isinstance(meshes, (str, bytes, os.PathLike)):
        # A lone path would otherwise be iterated: a job per character, each one failing.
        raise TypeError(f"meshes: expected a list of mesh paths, got one path {os.fsdecode(meshes)!r} (pass [path])")
    meshes = list(meshes)
    threads = _threads(threads, executor)
    out = Path(out_dir)
    options = {"landmarks": _landmarks(landmarks), "seed": _whole("seed", seed, 0, 2**64 - 1)}
    jobs = [
        Job("precompute", i, os.fspath(m), str(out / name), {"mesh": _abs(m)}, options, bool(overwrite), threads)
        for i, (m, name) in enumerate(zip(meshes, _names(meshes, ".wavg")))
    ]
    return _run("precompute", jobs, out, executor, progress, dict(options, threads=threads))


def _embedding_for(mesh: PathLike, given: PathLike | None, embeddings: Any) -> str | None:
    """The embedding of ``mesh``: the one given, else from ``embeddings`` (a precompute
    :class:`Manifest` or a folder holding ``NAME.wavg``), else ``None`` (precompute)."""
    if given is not None:
        return _abs(given)
    if embeddings is None:
        return None
    if isinstance(embeddings, Manifest):
        by_input = {_abs(k): v for k, v in embeddings.outputs().items()}
        found = by_input.get(_abs(mesh))
        return None if found is None else _abs(found)
    candidate = Path(embeddings) / (stem(mesh) + ".wavg")
    return _abs(candidate) if candidate.is_file() else None


def _split_template(template: Any) -> tuple[PathLike, PathLike | None]:
    if isinstance(template, (tuple, list)):
        if len(template) != 2:
            raise TypeError("template: expected a mesh path or a (mesh, embedding) pair")
        return template[0], template[1]
    return template, None


def _split_targets(targets: Sequence[Any]) -> list[tuple[PathLike, PathLike, PathLike | None]]:
    out = []
    for i, t in enumerate(targets):
        if not isinstance(t, (tuple, list)) or len(t) not in (2, 3):
            raise TypeError(f"targets[{i}]: expected a (mesh_path, anchors_path) pair or a (mesh, anchors, embedding) triple, got {t!r}")
        out.append((t[0], t[1], t[2] if len(t) == 3 else None))
    return out


def _template_embedding(
    template: PathLike, given: PathLike | None, embeddings: Any, out: Path, executor: Any, options: dict[str, Any], threads: int | None
) -> tuple[str | None, str | None]:
    """The template's embedding, precomputed once (as a job on the executor) into
    ``out/template/`` when none is given; ``(path, None)`` or ``(None, error)``."""
    found = _embedding_for(template, given, embeddings)
    if found is not None:
        return found, None
    opts = {"landmarks": options["landmarks"], "seed": 0}
    output = out / "template" / (stem(template) + ".wavg")
    job = Job("precompute", 0, os.fspath(template), str(output), {"mesh": _abs(template)}, opts, False, threads)
    (out / "template").mkdir(parents=True, exist_ok=True)
    store.sweep_temporaries(out / "template")
    r = run_all([job], executor)[0]
    if r["status"] == "failed":
        return None, f"template {os.fspath(template)}: {r['error']}"
    return _abs(output), None


def _pair_jobs(
    kind: str,
    template: Any,
    template_anchors: PathLike,
    targets: Sequence[Any],
    out_dir: PathLike,
    executor: Any,
    suffix: str,
    files: dict[str, PathLike],
    options: dict[str, Any],
    embeddings: Any,
    overwrite: bool,
    threads: int | None,
    progress: Progress | None,
) -> Manifest:
    """Shared body of :func:`transfer_all` and :func:`correspond_all`."""
    out = Path(out_dir)
    threads = _threads(threads, executor)
    tmesh, tgiven = _split_template(template)
    pairs = _split_targets(targets)
    out.mkdir(parents=True, exist_ok=True)
    temb, terror = _template_embedding(tmesh, tgiven, embeddings, out, executor, options, threads)
    common = {"template": _abs(tmesh), "template_embedding": temb, "template_anchors": _abs(template_anchors)}
    common.update({k: _abs(v) for k, v in files.items()})
    jobs, extra = [], []
    for i, ((mesh, anchors, emb), name) in enumerate(zip(pairs, _names([p[0] for p in pairs], suffix))):
        e = _embedding_for(mesh, emb, embeddings)
        f = dict(common, mesh=_abs(mesh), anchors=_abs(anchors), embedding=e)
        jobs.append(Job(kind, i, os.fspath(mesh), str(out / name), f, options, bool(overwrite), threads))
        extra.append({"anchors": os.fspath(anchors), "embedding": e})
    if terror is not None:  # nothing can run without the template: every job fails with why
        t0 = time.perf_counter()
        results = [{"status": "failed", "seconds": 0.0, "worker": None, "error": terror, "figures": {}} for _ in jobs]
        entries = [
            dict({"input": j.input, "output": j.output, "attempts": 0}, **{k: r[k] for k in ("status", "seconds", "worker", "error")}, **x)
            for j, r, x in zip(jobs, results, extra)
        ]
        m = Manifest(kind, entries, round(time.perf_counter() - t0, 6), options, version=store.package_version())
        m.write(out / "manifest.json")
        return m
    return _run(kind, jobs, out, executor, progress, dict(options, threads=threads, template_embedding=temb), extra)


def transfer_all(
    template: Any,
    template_texture: PathLike,
    template_anchors: PathLike,
    targets: Sequence[Any],
    out_dir: PathLike,
    executor: Any = None,
    *,
    size: int | tuple[int, int] | None = None,
    embeddings: Any = None,
    landmarks: int | None = None,
    overwrite: bool = False,
    threads: int | None = None,
    progress: Progress | None = None,
) -> Manifest:
    """Carries ``template_texture`` (a PNG on the template's UVs) onto each target's UV
    atlas: one RGBA PNG per target, ``out_dir/NAME.png``.

    ``template`` is a mesh path or a ``(mesh, embedding)`` pair; ``targets`` a list of
    ``(mesh_path, anchors_path)`` pairs (or ``(mesh, anchors, embedding)`` triples), anchor
    i of each file matching anchor i of ``template_anchors``. Embeddings not given are
    looked up in ``embeddings`` (the :class:`Manifest` of :func:`precompute_all` or its
    folder) and otherwise taken from the embedding cache or precomputed with ``landmarks``
    (None: the library's choice; the template's once, into ``out_dir/template/``). ``size``: the output's ``W`` or ``(W, H)`` (default: the
    texture's). Manifest figures: ``valid_fraction``, ``texels_per_s``, ``width``, ``height``.
    """
    options = {"landmarks": _landmarks(landmarks), "seed": 0, "size": _size(size)}
    return _pair_jobs(
        "transfer", template, template_anchors, targets, out_dir, executor, ".png",
        {"template_texture": template_texture}, options, embeddings, overwrite, threads, progress,
    )  # fmt: skip


def correspond_all(
    template: Any,
    template_anchors: PathLike,
    targets: Sequence[Any],
    out_dir: PathLike,
    executor: Any = None,
    *,
    validity: str = "local",
    embeddings: Any = None,
    landmarks: int | None = None,
    overwrite: bool = False,
    threads: int | None = None,
    progress: Progress | None = None,
) -> Manifest:
    """Maps every template vertex onto each target: one ``out_dir/NAME.npz`` per target
    with arrays ``face`` (int64), ``bary`` (n, 3), ``xyz`` (n, 3), ``valid`` (bool) and
    ``reason``, one row per template vertex (see ``wavg.correspond``).

    Arguments as :func:`transfer_all`'s; ``validity`` is ``wavg.correspond``'s. Manifest
    figures: ``valid_fraction``, ``vertices_per_s``.
    """
    if validity not in ("local", "paper"):
        raise ValueError(f'validity must be "local" or "paper", got {validity!r}')
    options = {"landmarks": _landmarks(landmarks), "seed": 0, "validity": validity}
    return _pair_jobs(
        "correspond", template, template_anchors, targets, out_dir, executor, ".npz",
        {}, options, embeddings, overwrite, threads, progress,
    )  # fmt: skip
