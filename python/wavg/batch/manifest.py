"""The record of a batch run: one entry per input, in input order, written atomically as
``out_dir/manifest.json``."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Iterator, Mapping, Sequence

from . import store

#: The statuses a job ends with.
STATUSES = ("done", "skipped", "failed")


class Manifest:
    """What a batch run did: ``jobs`` (dicts with ``input``, ``output``, ``status``,
    ``seconds``, ``worker``, ``error``, ``attempts`` and the job's figures, such as
    ``valid_fraction`` and ``texels_per_s``), the ``kind`` of job, the wall-clock
    ``seconds`` of the run and the ``path`` of its ``manifest.json``.

    Iterating yields the job entries; ``len`` is the number of inputs;
    ``manifest.counts`` the number of jobs per status; ``manifest.ok`` whether none failed.
    """

    def __init__(
        self,
        kind: str,
        jobs: Sequence[Mapping[str, Any]],
        seconds: float | None = None,
        options: Mapping[str, Any] | None = None,
        path: str | os.PathLike[str] | None = None,
        version: str | None = None,
    ):
        self.kind = kind
        self.jobs = [dict(j) for j in jobs]
        self.seconds = seconds
        self.options = dict(options or {})
        self.path = None if path is None else Path(path)
        self.version = version

    def __len__(self) -> int:
        return len(self.jobs)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        return iter(self.jobs)

    def __getitem__(self, i: int) -> dict[str, Any]:
        return self.jobs[i]

    def __repr__(self) -> str:
        counts = ", ".join(f"{k}={v}" for k, v in self.counts.items())
        return f"Manifest({self.kind!r}, {len(self)} jobs: {counts}, path={str(self.path)!r})"

    @property
    def counts(self) -> dict[str, int]:
        """Jobs per status (every status present, zero or not)."""
        out = {s: 0 for s in STATUSES}
        for j in self.jobs:
            out[j["status"]] = out.get(j["status"], 0) + 1
        return out

    @property
    def ok(self) -> bool:
        """True when no job failed."""
        return all(j["status"] != "failed" for j in self.jobs)

    @property
    def failed(self) -> list[dict[str, Any]]:
        """The entries of the failed jobs."""
        return [j for j in self.jobs if j["status"] == "failed"]

    def outputs(self) -> dict[str, str]:
        """Input -> output for every job whose output is there (``done`` or ``skipped``)."""
        return {j["input"]: j["output"] for j in self.jobs if j["status"] in ("done", "skipped")}

    def to_dict(self) -> dict[str, Any]:
        """The manifest as its JSON object."""
        return {
            "kind": self.kind,
            "version": self.version,
            "seconds": self.seconds,
            "counts": self.counts,
            "options": self.options,
            "jobs": self.jobs,
        }

    def write(self, path: str | os.PathLike[str] | None = None) -> Path:
        """Writes the manifest atomically to ``path`` (default: its own ``path``)."""
        target = Path(path) if path is not None else self.path
        if target is None:
            raise ValueError("path: the manifest has no path; give one")
        text = json.dumps(self.to_dict(), indent=1, default=str) + "\n"
        store.atomic_write_bytes(target, text.encode())
        self.path = target
        return target

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> "Manifest":
        """Reads a ``manifest.json`` written by a batch run."""
        d = json.loads(Path(path).read_text())
        if not isinstance(d, dict) or not isinstance(d.get("jobs"), list):
            raise ValueError(f"{path}: not a wavg.batch manifest (no 'jobs' list)")
        return cls(d.get("kind", ""), d["jobs"], d.get("seconds"), d.get("options"), path, d.get("version"))
