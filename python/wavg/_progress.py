"""The text progress bar of ``Surface.precompute`` (drawn only on a terminal)."""

import sys
import time


class TextBar:
    """A one-line bar on standard error: ``stage [#####.....] 42%  12.3 s``."""

    def __init__(self, stream=None, width: int = 30):
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.start = time.monotonic()
        self.drawn = False

    def __call__(self, stage: str, done: int, total: int) -> bool:
        frac = done / total if total else 0.0
        full = int(round(frac * self.width))
        line = "\r{:<9} [{}{}] {:3d}%  {:.1f} s".format(
            stage, "#" * full, "." * (self.width - full), int(frac * 100),
            time.monotonic() - self.start)
        self.stream.write(line)
        self.stream.flush()
        self.drawn = True
        return True

    def close(self) -> None:
        if self.drawn:
            self.stream.write("\n")
            self.stream.flush()


def terminal_bar():
    """A ``TextBar`` when standard error is a terminal, else None."""
    try:
        if sys.stderr is not None and sys.stderr.isatty():
            return TextBar()
    except (AttributeError, ValueError):
        pass
    return None
