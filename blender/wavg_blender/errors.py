"""The add-on's one error type and the import of the vendored ``wavg`` package."""

import os
import sys

VENDOR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "vendor")


class AddonError(Exception):
    """Bad input or a failed computation: its message goes to ``self.report({'ERROR'}, ...)``."""


def add_vendor_path():
    """Puts ``vendor/`` (the wheel's contents, unpacked at build time) on ``sys.path``."""
    if os.path.isdir(VENDOR) and VENDOR not in sys.path:
        sys.path.insert(0, VENDOR)


def wavg():
    """The ``wavg`` module, or an :class:`AddonError` saying why it cannot be imported."""
    add_vendor_path()
    try:
        import wavg as module
    except ImportError as e:
        raise AddonError(
            f"the wavg Python package cannot be imported ({e}); install the add-on from "
            "wavg_blender.zip, which ships it, and make sure NumPy is available"
        ) from e
    return module


def describe(e):
    """A one-line message for an exception raised by ``wavg``."""
    problems = getattr(e, "problems", None)
    if problems:
        shown = "; ".join(str(p) for p in list(problems)[:3])
        more = f" (and {len(problems) - 3} more)" if len(problems) > 3 else ""
        return f"{e}: {shown}{more}" if shown not in str(e) else str(e)
    return str(e) or type(e).__name__
