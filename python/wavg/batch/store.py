"""Outputs on disk: atomic writes, input fingerprints and the check that lets a job skip.

Every output ``OUT`` has a sidecar ``OUT.fingerprint.json`` holding the fingerprint of
everything the output was made from (input file bytes, options, package version) and the
SHA-256 of the output itself. A job is skipped only when both match, so a stale output
(changed input or options) and a corrupted one (bytes changed on disk) are both redone.
Both files are written to a temporary name in the same folder and renamed into place;
a job killed at any moment leaves at most a temporary file, which :func:`sweep_temporaries`
removes.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from pathlib import Path
from typing import Any, Callable, Mapping

#: Version of the fingerprint scheme; bump it when a job's output format changes.
SCHEME = 1
#: Marker in the names of temporary files, so that a sweep removes only ours.
TMP_MARK = ".wavg-tmp-"
#: Suffix of the sidecar that holds an output's fingerprint.
SIDECAR = ".fingerprint.json"


BUILTIN_PREFIX = "builtin:"


def file_digest(path: str | os.PathLike[str]) -> str:
    """SHA-256 of a file's bytes, hex; of the name for a builtin mesh (``builtin:torus``,
    made by the package, whose version is part of every fingerprint)."""
    name = os.fspath(path)
    if isinstance(name, str) and name.startswith(BUILTIN_PREFIX):
        return hashlib.sha256(name.encode()).hexdigest()
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def fingerprint(files: Mapping[str, str | os.PathLike[str] | None], options: Mapping[str, Any]) -> str:
    """Fingerprint of a job's inputs: the bytes of each named file, the options and the
    package version. ``None`` files count as absent (a distinct value)."""
    record = {
        "scheme": SCHEME,
        "version": package_version(),
        "files": {k: (None if p is None else file_digest(p)) for k, p in sorted(files.items())},
        "options": {k: options[k] for k in sorted(options)},
    }
    text = json.dumps(record, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def package_version() -> str:
    """The installed wavg's version (part of every fingerprint: a new version redoes all)."""
    import wavg

    version = getattr(wavg, "__version__", None)
    if version is None:
        from importlib.metadata import PackageNotFoundError, version as dist_version

        try:
            version = dist_version("wavg")
        except PackageNotFoundError:
            version = "unknown"
    return str(version)


def sidecar_path(output: str | os.PathLike[str]) -> Path:
    """Where the fingerprint of ``output`` is kept."""
    output = Path(output)
    return output.with_name(output.name + SIDECAR)


def _umask() -> int:
    """The process's umask, read without changing it (``os.umask`` would, racing threads)."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    return 0o022


def _make_temporary(path: Path, suffix: str = "") -> tuple[int, str]:
    """A new temporary file beside ``path`` with the permissions of a normally created file
    (``mkstemp`` makes it private, which would hide outputs from other cluster users)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix="." + path.name + TMP_MARK, suffix=suffix, dir=path.parent)
    os.fchmod(fd, 0o666 & ~_umask())
    return fd, tmp


def atomic_write(path: str | os.PathLike[str], write: Callable[[Any], None]) -> None:
    """Calls ``write(file)`` on a temporary binary file in ``path``'s folder, flushes it to
    disk and renames it to ``path``. On any error the temporary file is removed and
    ``path`` is untouched."""
    fd, tmp = _make_temporary(Path(path))
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Writes ``data`` to ``path`` atomically."""
    atomic_write(path, lambda f: f.write(data))


def temporary_path(path: str | os.PathLike[str]) -> Path:
    """A fresh temporary name in ``path``'s folder (for writers that take a file name);
    the caller renames it with :func:`commit` or removes it."""
    path = Path(path)
    fd, tmp = _make_temporary(path, path.suffix)
    os.close(fd)
    return Path(tmp)


def commit(tmp: str | os.PathLike[str], path: str | os.PathLike[str]) -> None:
    """Flushes ``tmp`` to disk and renames it to ``path``."""
    fd = os.open(tmp, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
    os.replace(tmp, path)


def record(output: str | os.PathLike[str], inputs: str, figures: Mapping[str, Any], run: str = "") -> None:
    """Writes ``output``'s sidecar: the input fingerprint, the output's digest, the
    figures the job reported (repeated in the manifest when a rerun skips the job) and the
    id of the batch run that made it."""
    side = {
        "run": run,
        "inputs": inputs,
        "output_sha256": file_digest(output),
        "output_bytes": os.path.getsize(output),
        "figures": dict(figures),
    }
    atomic_write_bytes(sidecar_path(output), json.dumps(side, sort_keys=True).encode())


def check(output: str | os.PathLike[str], inputs: str) -> tuple[dict[str, Any], str] | None:
    """The figures recorded for ``output`` and the id of the run that made it, when it
    exists, was made from inputs with fingerprint ``inputs`` and its bytes are intact;
    ``None`` when it must be (re)made."""
    output = Path(output)
    try:
        side = json.loads(sidecar_path(output).read_text())
        if side.get("inputs") != inputs or os.path.getsize(output) != side.get("output_bytes"):
            return None
        if file_digest(output) != side.get("output_sha256"):
            return None
        figures = side.get("figures")
        run = side.get("run")
        return (dict(figures) if isinstance(figures, dict) else {}), (run if isinstance(run, str) else "")
    except (OSError, ValueError, AttributeError):
        return None


def sweep_temporaries(folder: str | os.PathLike[str]) -> int:
    """Removes temporary files left in ``folder`` by jobs that were killed mid-write;
    returns how many. Run only when no job writes there."""
    n = 0
    try:
        entries = list(os.scandir(folder))
    except FileNotFoundError:
        return 0
    for e in entries:
        if e.is_file() and TMP_MARK in e.name and e.name.startswith("."):
            try:
                os.unlink(e.path)
                n += 1
            except FileNotFoundError:
                pass
    return n
