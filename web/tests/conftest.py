"""Fixtures of the browser tests: a `wavg serve` process and Debian's chromium driven by
Playwright (never Playwright's own browsers), on a temporary profile (Playwright's
`launch`, never the user's; `test_profile.py` checks it).

Environment: WAVG_BIN (the `wavg` binary; default target/debug/wavg of this repository),
WAVG_SERVE_MESH (default builtin:torus), WAVG_BENCH_MESH (a ~100k-face mesh for the
measurements; they are skipped without it), CHROMIUM (default /usr/bin/chromium).
"""

import json
import os
import pathlib
import subprocess
import time
import urllib.request

import pytest
from playwright.sync_api import sync_playwright

ROOT = pathlib.Path(__file__).resolve().parents[2]
CHROMIUM = os.environ.get("CHROMIUM", "/usr/bin/chromium")
ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--enable-unsafe-swiftshader",
    "--use-angle=swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-default-apps",
    "--disable-extensions",
    "--disable-sync",
    "--no-first-run",
    "--metrics-recording-only",
    "--disable-dev-shm-usage",
]


def wavg_bin():
    return os.environ.get("WAVG_BIN", str(ROOT / "target" / "debug" / "wavg"))


class Server:
    """A running `wavg serve MESH --port 0`; `url` is where it listens."""

    def __init__(self, mesh, extra=()):
        # An embedding the server computes goes to a cache folder of the build, not $HOME's.
        env = {**os.environ, "WAVG_CACHE_DIR": os.environ.get("WAVG_CACHE_DIR", str(ROOT / "target" / "web-cache"))}
        self.proc = subprocess.Popen(
            [wavg_bin(), "serve", mesh, "--port", "0", *extra],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        line = self.proc.stdout.readline()
        if "serving " not in line:
            self.proc.kill()
            raise RuntimeError(f"wavg serve did not start: {line!r} {self.proc.stderr.read()}")
        self.url = line.split("serving ")[1].split()[0].rstrip("/")
        self.wait_ready()

    def wait_ready(self, timeout=600):
        end = time.time() + timeout
        while time.time() < end:
            if self.get_json("/api/status")["state"] == "ready":
                return
            time.sleep(0.2)
        raise RuntimeError("the embedding was not ready in time")

    def get_json(self, path):
        with urllib.request.urlopen(self.url + path, timeout=60) as r:
            return json.load(r)

    def post(self, path, body, raw=False):
        data = body if isinstance(body, bytes) else json.dumps(body).encode()
        req = urllib.request.Request(self.url + path, data=data, method="POST")
        try:
            with urllib.request.urlopen(req, timeout=120) as r:
                payload = r.read()
                return r.status, payload if raw else json.loads(payload)
        except urllib.error.HTTPError as e:
            return e.code, json.loads(e.read())

    def stop(self):
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()


@pytest.fixture(scope="session")
def server():
    s = Server(os.environ.get("WAVG_SERVE_MESH", "builtin:torus"))
    yield s
    s.stop()


@pytest.fixture(scope="session")
def browser():
    if not os.path.exists(CHROMIUM):
        pytest.skip(f"SKIPPED browser tests: {CHROMIUM} not installed (apt-get install chromium)")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=ARGS)
        yield b
        b.close()


class Page:
    """A page of the server with its console errors collected."""

    def __init__(self, browser, server, width=1100, height=760):
        self.context = browser.new_context(viewport={"width": width, "height": height}, accept_downloads=True)
        self.page = self.context.new_page()
        self.errors = []
        self.page.on("console", lambda m: m.type == "error" and self.errors.append(m.text))
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.pending = {}
        self.page.on("request", lambda r: self.pending.__setitem__(id(r), r.url))
        self.page.on("requestfinished", lambda r: self.pending.pop(id(r), None))
        self.page.on("requestfailed", lambda r: self.errors.append(f"{r.url}: {r.failure}"))
        self.page.goto(server.url + "/", wait_until="commit")
        try:
            self.page.wait_for_function("window.wavg && window.wavg.ready", timeout=60_000)
        except Exception as e:
            status = self.page.evaluate("document.getElementById('status').textContent")
            raise RuntimeError(
                f"page not ready; pending requests {list(self.pending.values())}, "
                f"errors {self.errors}, status {status!r}"
            ) from e

    def js(self, expr, arg=None):
        return self.page.evaluate(expr, arg)

    def idle(self):
        """Waits until no request is in flight or pending."""
        self.page.wait_for_function("!window.wavg.modes.busy && !window.wavg.modes.dirty", timeout=120_000)

    def visible_vertices(self, count, spread=1):
        """Screen positions of `count` vertices the camera sees, spread over the mesh."""
        return self.js(
            """([count, spread]) => {
                const w = window.wavg; const n = w.mesh.n; const out = [];
                for (let k = 0; out.length < count && k < 4 * n; k++) {
                    const v = Math.floor((k * 7919 * spread) % n);
                    const s = w.surfaceScreen(v);
                    if (s && out.every((o) => Math.hypot(o.x - s.x, o.y - s.y) > 60)) out.push({ v, ...s });
                }
                return out;
            }""",
            [count, spread],
        )

    def close(self):
        self.context.close()


@pytest.fixture
def page(browser, server):
    p = Page(browser, server)
    yield p
    p.close()
