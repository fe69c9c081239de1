"""``python -m wavg.batch precompute|transfer|correspond ...``: the batch functions from
the command line, in-process or on Dask (``--local N`` starts a local cluster of N
single-thread worker processes; ``--scheduler ADDRESS`` connects to a running one).

Prints a progress bar (jobs finished / total, failures) on standard error and the
manifest's path at the end on standard output. Exit status: 0 when every job is done or
skipped, 1 when any failed, 2 for bad arguments.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import time
from pathlib import Path
from typing import Any, Iterator, TextIO

from . import correspond_all, precompute_all, transfer_all


class Bar:
    """A one-line progress bar (redrawn in place on a terminal, a line per tenth otherwise)."""

    def __init__(self, label: str, stream: TextIO | None = None, width: int = 30):
        self.label, self.width = label, width
        self.stream = stream if stream is not None else sys.stderr
        self.tty = self.stream.isatty()
        self.t0 = time.perf_counter()
        self.last_tenth = -1

    def __call__(self, finished: int, total: int, failed: int) -> None:
        frac = finished / total if total else 1.0
        fill = int(round(frac * self.width))
        elapsed = time.perf_counter() - self.t0
        line = (
            f"{self.label} [{'#' * fill}{'.' * (self.width - fill)}] {finished}/{total} jobs, "
            f"{failed} failed, {elapsed:.0f} s"
        )
        if self.tty:
            self.stream.write("\r" + line + ("\n" if finished == total else ""))
        else:
            tenth = int(frac * 10)
            if tenth == self.last_tenth:
                return
            self.last_tenth = tenth
            self.stream.write(line + "\n")
        self.stream.flush()


def _size(text: str) -> int | tuple[int, int]:
    """``W`` or ``WxH``."""
    parts = text.lower().split("x")
    try:
        nums = [int(p) for p in parts]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected W or WxH, got {text!r}") from None
    if len(nums) == 1 and nums[0] > 0:
        return nums[0]
    if len(nums) == 2 and min(nums) > 0:
        return nums[0], nums[1]
    raise argparse.ArgumentTypeError(f"expected W or WxH with positive numbers, got {text!r}")


def _lines(path: str) -> list[list[str]]:
    """Whitespace-separated fields of each non-blank, non-comment line; relative paths are
    taken relative to the list file's folder."""
    base = Path(path).parent
    rows = []
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        fields = line.split("#", 1)[0].split()
        if fields:
            rows.append([f if Path(f).is_absolute() else str(base / f) for f in fields])
    return rows


@contextlib.contextmanager
def _executor(args: argparse.Namespace) -> Iterator[Any]:
    """A Dask client for ``--scheduler``/``--local``, else ``None`` (in-process)."""
    if args.scheduler is None and args.local is None:
        yield None
        return
    import dask
    from distributed import Client, LocalCluster

    if args.scheduler is not None:
        with Client(args.scheduler) as client:
            yield client
        return
    # No dashboard, so the workers' statistical profiler would sample stacks for nobody.
    with dask.config.set({"distributed.worker.profile.enabled": False}):
        cluster = LocalCluster(n_workers=args.local, threads_per_worker=1, processes=True, dashboard_address=None)
    with cluster, Client(cluster) as client:
        yield client


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m wavg.batch", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True)

    def common(s: argparse.ArgumentParser) -> None:
        s.add_argument("-o", "--out", required=True, help="Output folder (created if missing)")
        where = s.add_mutually_exclusive_group()
        where.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler to run on (tcp://host:8786)")
        where.add_argument("--local", type=int, metavar="N", help="Run on a local Dask cluster of N worker processes")
        s.add_argument("--threads", type=int, help="Threads per job (default: 1 on Dask, all cores in-process)")
        s.add_argument("--landmarks", type=int, default=None, help="Landmarks of embeddings precomputed here (default: the library's choice)")
        s.add_argument("--overwrite", action="store_true", help="Redo outputs that are up to date")

    pre = sub.add_parser("precompute", help="Precompute the embedding of every mesh (NAME.wavg)")
    pre.add_argument("meshes", nargs="*", help="Mesh files")
    pre.add_argument("--list", metavar="FILE", help="A file with one mesh path per line (added after MESHES)")
    common(pre)

    for name, what in (("transfer", "Carry a texture onto each target (NAME.png)"), ("correspond", "Map the template's vertices onto each target (NAME.npz)")):
        s = sub.add_parser(name, help=what)
        s.add_argument("--template", required=True, help="Template mesh")
        s.add_argument("--template-anchors", required=True, help="Anchors on the template (v VERTEX or f FACE B0 B1 B2 per line)")
        s.add_argument("--template-embedding", help="The template's .wavg (default: precomputed once)")
        if name == "transfer":
            s.add_argument("--texture", required=True, help="The template's texture (PNG)")
            s.add_argument("--size", type=_size, help="Output size W or WxH (default: the texture's)")
        else:
            s.add_argument("--validity", default="local", choices=("local", "paper"), help="Which images to keep (default local)")
        s.add_argument("--target", nargs=2, action="append", default=[], metavar=("MESH", "ANCHORS"), help="A target mesh and its anchors (repeatable)")
        s.add_argument("--targets", metavar="FILE", help="A file with 'MESH ANCHORS [EMBEDDING]' per line (after the --target pairs)")
        s.add_argument("--embeddings", metavar="DIR", help="Folder of NAME.wavg embeddings (precompute's output)")
        common(s)
    return p


def _check_dask(p: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Exits with a usage error (status 2) when ``--scheduler``/``--local`` is given and
    Dask's distributed scheduler cannot be imported, before any work starts."""
    if args.scheduler is None and args.local is None:
        return
    try:
        import dask  # noqa: F401
        import distributed  # noqa: F401
    except ImportError as e:
        option = "--scheduler" if args.scheduler is not None else "--local"
        p.error(f"{option} runs on Dask, which is not installed ({e}): pip install 'dask[distributed]', or leave {option} out to run in this process")
    if args.local is not None and args.local < 1:
        p.error(f"--local needs at least 1 worker process, got {args.local}")


def main(argv: list[str] | None = None) -> int:
    """Runs the command line; returns the exit status."""
    p = _parser()
    args = p.parse_args(argv)
    _check_dask(p, args)
    bar = Bar(args.command)
    if args.command == "precompute":
        meshes = list(args.meshes) + ([r[0] for r in _lines(args.list)] if args.list else [])
        if not meshes:
            p.error("precompute: no meshes (give MESHES or --list FILE)")
        with _executor(args) as ex:
            m = precompute_all(meshes, args.out, ex, args.landmarks, args.overwrite, threads=args.threads, progress=bar)
    else:
        targets: list[tuple[str, ...]] = [tuple(t) for t in args.target]
        if args.targets:
            for row in _lines(args.targets):
                if len(row) not in (2, 3):
                    p.error(f"{args.targets}: expected 'MESH ANCHORS [EMBEDDING]' per line, got {' '.join(row)!r}")
                targets.append(tuple(row))
        if not targets:
            p.error(f"{args.command}: no targets (give --target MESH ANCHORS or --targets FILE)")
        template = (args.template, args.template_embedding) if args.template_embedding else args.template
        kw = dict(embeddings=args.embeddings, landmarks=args.landmarks, overwrite=args.overwrite, threads=args.threads, progress=bar)
        with _executor(args) as ex:
            if args.command == "transfer":
                m = transfer_all(template, args.texture, args.template_anchors, targets, args.out, ex, size=args.size, **kw)
            else:
                m = correspond_all(template, args.template_anchors, targets, args.out, ex, validity=args.validity, **kw)
    counts = m.counts
    for j in m.failed:
        print(f"failed: {j['input']}: {j['error']}", file=sys.stderr)
    print(f"{counts['done']} done, {counts['skipped']} skipped, {counts['failed']} failed in {m.seconds:.1f} s", file=sys.stderr)
    print(m.path)
    return 0 if m.ok else 1


if __name__ == "__main__":
    sys.exit(main())
