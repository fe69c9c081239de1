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


_MODULE = []


def wavg():
    """The ``wavg`` module, or an :class:`AddonError` saying why it cannot be imported
    (looked up once: live updates call this at every move)."""
    if _MODULE:
        return _MODULE[0]
    add_vendor_path()
    try:
        import wavg as module
    except ImportError as e:
        raise AddonError(
            f"the wavg Python package cannot be imported ({e}); install the add-on from "
            "wavg_blender.zip, which ships it, and make sure NumPy is available"
        ) from e
    _MODULE.append(module)
    return module


def describe(e):
    """A one-line message for an exception raised by ``wavg`` (with the first problems of
    an invalid mesh when the message does not already list them)."""
    text = str(e) or type(e).__name__
    problems = [str(p) for p in (getattr(e, "problems", None) or [])]
    if not problems or any(p in text for p in problems):
        return text
    more = f" (and {len(problems) - 3} more)" if len(problems) > 3 else ""
    return f"{text}: {'; '.join(problems[:3])}{more}"
