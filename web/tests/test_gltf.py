"""`wavg serve scene.glb`: the page loads a glTF file (a torus cut along its UV seams, as
exporters write it) as one welded surface and draws it."""

import sys
from pathlib import Path

from conftest import Page, Server
from test_page import SNAP

# The seamed torus is lab/tools/torus_glb.py's (also the glTF load benchmark's file).
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lab" / "tools"))
from torus_glb import torus_glb  # noqa: E402


def test_the_page_loads_a_glb_as_one_welded_surface(browser, tmp_path):
    nu, nv = 32, 12
    path = tmp_path / "torus.glb"
    path.write_bytes(torus_glb(nu, nv))
    server = Server(f"{path}#Torus")
    try:
        page = Page(browser, server)
        info = page.js("document.getElementById('meshinfo').textContent")
        assert info == f"{nu * nv} vertices, {2 * nu * nv} faces"
        assert page.js(SNAP, "glb")["painted"] > 0.05
        assert page.errors == []
        page.close()
    finally:
        server.stop()
