"""The page in a real browser (Debian's chromium, software GL): it loads cleanly, real
mouse events add and drag anchors and the curve drawn is the API's, every mode draws
something different, the downloads are the command line's files, and malformed requests
leave the server answering."""

import os
import pathlib
import subprocess

import pytest

from conftest import ROOT, wavg_bin

# Pixel statistics of the WebGL canvas, computed in the page (full resolution).
SNAP = """(name) => {
    window.wavg.render(); // draw, then read
    const c = window.wavg.renderer.domElement;
    const g = document.createElement('canvas');
    g.width = c.width; g.height = c.height;
    const ctx = g.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
    window.__snaps = window.__snaps || {};
    window.__snaps[name] = d;
    let painted = 0; const colours = new Set();
    for (let i = 0; i < d.length; i += 4) {
        if (Math.abs(d[i] - 244) + Math.abs(d[i + 1] - 244) + Math.abs(d[i + 2] - 242) > 12) painted++;
        colours.add((d[i] >> 3) << 10 | (d[i + 1] >> 3) << 5 | (d[i + 2] >> 3));
    }
    return { painted: painted / (d.length / 4), colours: colours.size };
}"""

DIFF = """([a, b]) => {
    const x = window.__snaps[a]; const y = window.__snaps[b]; let n = 0;
    for (let i = 0; i < x.length; i += 4) {
        if (Math.abs(x[i] - y[i]) + Math.abs(x[i + 1] - y[i + 1]) + Math.abs(x[i + 2] - y[i + 2]) > 24) n++;
    }
    return n;
}"""


def add_anchors(page, count):
    """Clicks `count` visible vertices (real mouse events); returns their screen spots."""
    spots = page.visible_vertices(count)
    assert len(spots) == count, spots
    for s in spots:
        page.page.mouse.click(s["x"], s["y"])
        page.idle()
    assert page.js("window.wavg.anchors.length") == count
    return spots


def drag_anchor(page, index, target, steps, settle_each=False):
    """Drags anchor ``index`` to the screen point ``target`` with real mouse events in
    ``steps`` moves (letting each frame finish when ``settle_each``), then lets the page
    settle."""
    start = page.js(f"window.wavg.anchorScreen({index})")
    m = page.page.mouse
    m.move(start["x"], start["y"])
    m.down()
    for k in range(1, steps + 1):
        m.move(start["x"] + (target["x"] - start["x"]) * k / steps, start["y"] + (target["y"] - start["y"]) * k / steps)
        if settle_each:
            page.idle()
    m.up()
    page.idle()


def test_page_loads_without_console_errors(page):
    assert page.js("window.wavg.stats.readyMs") > 0
    assert page.js("document.getElementById('meshinfo').textContent").endswith("faces")
    page.page.wait_for_timeout(300)
    assert page.errors == []


def test_clicks_and_drags_change_the_spline_as_the_api_computes_it(page, server):
    add_anchors(page, 5)
    body = page.js("window.wavg.modes.splineBody()")
    drawn = page.js("window.wavg.modes.last.spline")
    status, want = server.post("/api/spline", body)
    assert status == 200
    assert drawn == want["points"]
    assert sum(p is not None for p in drawn) == body["samples"]
    # Drag anchor 2 to a free spot of the surface with real mouse events.
    target = page.visible_vertices(7)[6]
    before = page.js("window.wavg.anchors[2].point")
    drag_anchor(page, 2, target, 20)
    after = page.js("window.wavg.anchors[2].point")
    assert after != before
    moved = page.js("window.wavg.anchorScreen(2)")
    assert abs(moved["x"] - target["x"]) < 2 and abs(moved["y"] - target["y"]) < 2
    body2 = page.js("window.wavg.modes.splineBody()")
    assert body2["control"][2] == after
    status, want2 = server.post("/api/spline", body2)
    assert page.js("window.wavg.modes.last.spline") == want2["points"]
    assert want2["points"] != want["points"]
    # Orbiting (a drag away from anchors) adds nothing.
    m = page.page.mouse
    m.move(20, 20)
    m.down()
    m.move(120, 60, steps=5)
    m.up()
    assert page.js("window.wavg.anchors.length") == 5
    assert page.errors == []


def test_a_drag_frame_equals_a_full_redraw(page):
    """A frame during a drag erases the previous overlay and draws the new one; the pixels
    must be those of the whole canvas redrawn from the cached mesh (no trail left)."""
    add_anchors(page, 5)
    target = page.visible_vertices(7)[6]
    drag_anchor(page, 1, target, 10, settle_each=True)
    grab = """() => { const c = window.wavg.renderer.domElement; const g = document.createElement('canvas');
        g.width = c.width; g.height = c.height; const ctx = g.getContext('2d'); ctx.drawImage(c, 0, 0);
        window.__grab = ctx.getImageData(0, 0, c.width, c.height).data; }"""
    page.js(grab)  # the canvas as the drag's partial frames left it
    assert page.js("window.__grab.length") > 0
    page.js("window.wavg.render(true)")
    diff = page.js(
        "(p) => { const c = window.wavg.renderer.domElement; const g = document.createElement('canvas');"
        " g.width = c.width; g.height = c.height; const ctx = g.getContext('2d'); ctx.drawImage(c, 0, 0);"
        " const d = ctx.getImageData(0, 0, c.width, c.height).data; let n = 0;"
        " for (let i = 0; i < d.length; i++) if (d[i] !== window.__grab[i]) n++; return n; }"
    )
    assert diff == 0, f"{diff} channel values differ between the drag's frame and a full redraw"
    assert page.errors == []


def test_weight_sliders_move_the_average(page, server):
    add_anchors(page, 4)
    page.page.select_option("#mode", "average")
    page.idle()
    first = page.js("window.wavg.modes.last.average")
    assert first is not None
    slider = page.page.locator("#anchors input[type=range]").nth(0)
    slider.fill("0.1")
    page.idle()
    second = page.js("window.wavg.modes.last.average")
    assert second != first
    anchors = page.js("window.wavg.modes.anchorPoints()")
    status, want = server.post(
        "/api/forward", {"anchors": anchors, "weights": [[0.1, 1, 1, 1]], "normalize": True}
    )
    assert want["points"][0] == second
    assert page.errors == []


def test_every_mode_draws_something_different(page):
    add_anchors(page, 5)
    stats = {}
    for mode in ["spline", "average", "decal", "distance", "remesh"]:
        page.page.select_option("#mode", mode)
        page.idle()
        assert "error" not in page.js("document.getElementById('status').className"), mode
        stats[mode] = page.js(SNAP, mode)
        out = ROOT / "target" / "web-shots"
        out.mkdir(parents=True, exist_ok=True)
        page.page.screenshot(path=str(out / f"{mode}.png"))
    for mode, s in stats.items():
        assert s["painted"] > 0.05 and s["colours"] > 20, (mode, s)
    modes = list(stats)
    for i, a in enumerate(modes):
        for b in modes[i + 1 :]:
            assert page.js(DIFF, [a, b]) > 50, (a, b)
    # The decal and distance modes colour the surface: many more colours than shading.
    assert stats["distance"]["colours"] > stats["spline"]["colours"]
    assert page.errors == []


def download(page, button):
    with page.page.expect_download() as d:
        page.page.click(button)
    return pathlib.Path(d.value.path()).read_text()


def test_downloads_are_the_command_lines_files(page, server, tmp_path):
    add_anchors(page, 5)
    page.idle()
    curve = download(page, "#dl-curve")
    body = page.js("window.wavg.modes.splineBody()")
    rows = [line.split() for line in curve.splitlines()]
    assert len(rows) == body["samples"]
    assert all(len(r) == 7 and int(r[0]) >= 0 for r in rows)
    drawn = page.js("window.wavg.modes.last.spline")
    for r, p in zip(rows, drawn):
        assert [float(x) for x in r[1:]] == pytest.approx(p[1:], abs=1e-12)
    # `wavg spline` with the same control points writes the same file.
    mesh = os.environ.get("WAVG_SERVE_MESH", "builtin:torus")
    if os.environ.get("WAVG_SERVE_EMBEDDING") is None:
        control = tmp_path / "control.txt"
        control.write_text("".join(f"f {c[0]} {c[1]!r} {c[2]!r} {c[3]!r}\n" for c in body["control"]))
        out = tmp_path / "cli.txt"
        subprocess.run(
            [wavg_bin(), "spline", "--mesh", mesh, "--control", str(control), "--samples",
             str(body["samples"]), "-o", str(out)],
            check=True, capture_output=True,
        )
        assert out.read_text() == curve
    info = server.get_json("/api/info")
    page.page.select_option("#mode", "decal")
    page.idle()
    obj = download(page, "#dl-decal").splitlines()
    assert sum(line.startswith("v ") for line in obj) == info["vertices"]
    assert sum(line.startswith("vt ") for line in obj) == info["vertices"]
    faces = [line for line in obj if line.startswith("f ")]
    assert len(faces) == info["faces"] and all(len(f.split()) == 4 for f in faces)
    # A face with a marked corner has no texture coordinates (it shows untextured).
    marked = set(page.js("window.wavg.modes.last.decal.marked"))
    assert marked, "this decal marks no vertex: the test shows nothing"
    for f in faces:
        corners = [int(c.split("/")[0]) - 1 for c in f.split()[1:]]
        assert ("/" in f) == (not marked.intersection(corners)), f
    uv = page.js("window.wavg.modes.last.decal.uv")
    vts = [float(x) for line in obj if line.startswith("vt ") for x in line.split()[1:]]
    assert vts == pytest.approx([x for p in uv for x in p], abs=1e-12)
    # `wavg decal` with the same anchors and (u, v) writes the same file.
    if os.environ.get("WAVG_SERVE_EMBEDDING") is None:
        body = page.js("window.wavg.modes.decalBody()")
        anchors, uvs = tmp_path / "anchors.txt", tmp_path / "uv.txt"
        anchors.write_text("".join(
            f"v {a}\n" if isinstance(a, int) else f"f {a[0]} {a[1]!r} {a[2]!r} {a[3]!r}\n"
            for a in body["anchors"]))
        uvs.write_text("".join(f"{u!r} {v!r}\n" for u, v in body["uv"]))
        cli = subprocess.run(
            [wavg_bin(), "decal", "--mesh", mesh, "--anchors", str(anchors), "--uv", str(uvs),
             "--max-negative", repr(body.get("max_negative", -0.1)), "-o", "-"],
            check=True, capture_output=True, text=True,
        ).stdout
        assert cli.splitlines() == obj
    page.page.select_option("#mode", "remesh")
    page.idle()
    obj = download(page, "#dl-remesh").splitlines()
    last = page.js("window.wavg.modes.last.remesh")
    assert sum(line.startswith("v ") for line in obj) == len(last["vertices"])
    assert sum(line.startswith("f ") for line in obj) == len(last["faces"])
    assert page.errors == []


def test_dragging_a_cage_vertex_remeshes(page):
    page.page.select_option("#mode", "remesh")
    page.idle()
    before = page.js("window.wavg.modes.last.remesh.vertices")
    spot = page.js(
        """() => { const m = window.wavg.modes; const w = window.wavg;
            for (const p of m.cage.vertices) {
                const v = new w.THREE.Vector3(...p).project(w.camera);
                const r = w.renderer.domElement.getBoundingClientRect();
                const s = { x: r.left + (v.x + 1) / 2 * r.width, y: r.top + (1 - v.y) / 2 * r.height };
                if (m.handleAt(s.x, s.y) && w.hitAt(s.x + 15, s.y + 10)) return s;
            }
            return null; }"""
    )
    assert spot is not None
    m = page.page.mouse
    m.move(spot["x"], spot["y"])
    m.down()
    m.move(spot["x"] + 15, spot["y"] + 10, steps=5)
    m.up()
    page.idle()
    assert page.js("window.wavg.modes.last.remesh.vertices") != before
    assert page.errors == []


def test_malformed_api_requests_leave_the_server_answering(page, server):
    bad = [b"", b"{", b"[]", b"null", b'{"anchors": "x"}', b"\xff\xfe", b'{"control": [0, 1e999]}']
    routes = ["/api/forward", "/api/inverse", "/api/spline", "/api/decal", "/api/distance", "/api/remesh"]
    n = 0
    while n < 200:
        route = routes[n % len(routes)]
        body = bad[(n // len(routes)) % len(bad)]
        status, answer = server.post(route, body)
        assert 400 <= status < 500 and answer["error"], (route, body, status)
        n += 1
    assert server.get_json("/api/info")["faces"] > 0
    # The page still works: a click adds an anchor.
    add_anchors(page, 1)
    assert page.errors == []


def test_readme_screenshot(browser, server):
    """The picture of the README (written to docs/images/serve.png with
    WAVG_UPDATE_SCREENSHOT=1, else under target/)."""
    from conftest import Page

    p = Page(browser, server, 820, 460)
    try:
        add_anchors(p, 5)
        p.page.check("#closed")
        p.idle()
        path = ROOT / "target" / "web-shots" / "serve.png"
        if os.environ.get("WAVG_UPDATE_SCREENSHOT") == "1":
            path = ROOT / "docs" / "images" / "serve.png"
        path.parent.mkdir(parents=True, exist_ok=True)
        p.page.screenshot(path=str(path))
        assert path.stat().st_size > 10_000
        assert p.errors == []
    finally:
        p.close()
