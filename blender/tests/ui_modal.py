"""The interactive precompute in a real Blender window (not background mode): its modal
operator runs wavg in a worker thread, shows progress in the status bar, and Esc cancels;
then making the mesh active reads its embedding ahead (a subscription to the active object,
which only a window's event loop delivers), and after an edit of a decal's anchors the idle
timer reads the decal ahead, which the next click takes.
Needs a display (Xvfb is enough) and Blender's event simulation:

    xvfb-run -a blender --factory-startup --enable-event-simulate \\
        --python blender/tests/ui_modal.py -- --zip target/wavg_blender.zip

Prints `ok`/`FAILED` lines and exits 0 when every check passed, 1 otherwise.
"""

import math
import os
import shutil
import sys
import tempfile
import threading
import time
import traceback

import bmesh
import bpy
import numpy as np

ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ZIP = os.path.abspath(ARGS[ARGS.index("--zip") + 1])
TMP = tempfile.mkdtemp(prefix="wavg-blender-ui-")
os.environ["WAVG_BLENDER_CACHE"] = os.path.join(TMP, "cache")
FAILURES = []
STATE = {}


def check(name, ok, detail=""):
    print(f"{'ok    ' if ok else 'FAILED'} {name} {detail}", flush=True)
    if not ok:
        FAILURES.append(name)


def finish():
    print(f"{'all passed' if not FAILURES else 'failed: ' + ', '.join(FAILURES)}", flush=True)
    if os.environ.get("WAVG_KEEP_TEST_FILES"):
        print(f"test files kept in {TMP}", flush=True)
    else:
        shutil.rmtree(TMP, ignore_errors=True)
    os._exit(1 if FAILURES else 0)


def watch_esc():
    """Records when the operator receives Esc and when its worker ends: Blender's simulated
    events reach a modal operator, and timers fire, seconds late on a busy machine, which is
    not the add-on's latency."""
    from wavg_blender import op_precompute

    modal = op_precompute.WAVG_OT_precompute.modal

    def recorded(self, context, event):
        if event.type == 'ESC':
            STATE.setdefault("esc_seen", time.time())
        return modal(self, context, event)

    op_precompute.WAVG_OT_precompute.modal = recorded
    run = op_precompute._Job.run

    def timed_run(self):
        run(self)
        STATE.setdefault("worker_ended", time.time())

    op_precompute._Job.run = timed_run


def setup():
    scripts = os.path.join(TMP, "scripts")
    os.makedirs(os.path.join(scripts, "addons"))
    bpy.context.preferences.filepaths.script_directory = scripts
    bpy.utils.refresh_script_paths()
    bpy.ops.preferences.addon_install(filepath=ZIP, target='PREFS')
    bpy.ops.preferences.addon_enable(module="wavg_blender")
    watch_esc()
    bm = bmesh.new()
    bmesh.ops.create_icosphere(bm, subdivisions=5, radius=1.0)
    me = bpy.data.meshes.new("big")
    bm.to_mesh(me)
    bm.free()
    obj = bpy.data.objects.new("big", me)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj


def decal_anchors(obj):
    """A vertex group ``wavg_anchors`` of 8 vertices around the top, their (u, v) in the
    point attribute ``wavg_uv`` (the first one's also on the vertex after it, where the
    test moves it); returns the anchor ids."""
    me = obj.data
    V = np.empty(3 * len(me.vertices), dtype=np.float32)
    me.vertices.foreach_get("co", V)
    V = V.reshape(-1, 3)
    ids = sorted({int(np.argmax(V @ np.array([math.cos(t), math.sin(t), 2.0])))
                  for t in np.linspace(0, 2 * math.pi, 8, endpoint=False)})
    obj.vertex_groups.new(name="wavg_anchors").add(ids, 1.0, 'REPLACE')
    uv = np.zeros((len(V), 2), dtype=np.float32)
    for k, i in enumerate(ids):
        uv[i] = (0.5 + 0.5 * math.cos(k), 0.5 + 0.5 * math.sin(k))
    assert ids[0] + 1 not in ids
    uv[ids[0] + 1] = uv[ids[0]]
    me.attributes.new("wavg_uv", 'FLOAT2', 'POINT').data.foreach_set("vector", uv.ravel())
    return ids


def start_precompute():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    with bpy.context.temp_override(window=win, area=area):
        result = bpy.ops.wavg.precompute('INVOKE_DEFAULT')
    return win, result


def cache_files():
    d = os.environ["WAVG_BLENDER_CACHE"]
    return sorted(os.listdir(d)) if os.path.isdir(d) else []


def step():
    """A state machine driven by a timer: start, press Esc, check, start again, wait."""
    try:
        phase = STATE.setdefault("phase", "start")
        obj = bpy.data.objects["big"]
        if phase == "start":
            STATE["threads"] = threading.active_count()
            win, result = start_precompute()
            check("the worker thread runs", threading.active_count() == STATE["threads"] + 1)
            check("invoke starts a modal precompute", result == {'RUNNING_MODAL'}, str(result))
            STATE.update(phase="esc", win=win, t=time.time())
            return 0.3
        if phase == "esc":
            STATE["win"].event_simulate(type='ESC', value='PRESS')
            STATE["win"].event_simulate(type='ESC', value='RELEASE')
            STATE.update(phase="cancelled", t=time.time())
            return 0.2
        if phase == "cancelled":
            # Had Esc not cancelled it, the worker would end by writing the cache file.
            stopped = threading.active_count() == STATE["threads"]
            if not stopped and time.time() - STATE["t"] < 120.0:
                return 0.1
            now = time.time()
            seen = STATE.get("esc_seen", now)
            ended = STATE.get("worker_ended", now)
            # The callable is polled ten times a second and a cancelled call returns at
            # once; 1 s leaves room for a loaded machine's timers.
            check("Esc stops the worker within 1 s of reaching the operator", stopped and ended - seen < 1.0,
                  f"(after {ended - seen:.2f} s; the simulated event took {seen - STATE['t']:.1f} s to arrive)")
            check("Esc cancels: nothing written", "wavg_key" not in obj and not cache_files(),
                  str(cache_files()))
            win, result = start_precompute()
            STATE.update(phase="wait", t=time.time())
            return 0.5
        if phase == "wait":
            if "wavg_key" not in obj:
                if time.time() - STATE["t"] > 240:
                    check("precompute finishes", False, "timed out")
                    finish()
                return 0.5
            print(f"       a whole precompute took {time.time() - STATE['t']:.1f} s")
            files = cache_files()
            # One entry of the shared cache: KEY.wavg and its description KEY.json.
            entry = os.path.basename(obj.get("wavg_embedding", ""))
            stem = entry[: -len(".wavg")] if entry.endswith(".wavg") else entry
            check("precompute finishes and writes the cache", entry and files == [stem + ".json", entry],
                  str(files))
            from wavg_blender import surfaces

            # Made active again (as a click does), the mesh's embedding is read ahead.
            surfaces.forget_all()
            bpy.context.view_layer.objects.active = None
            bpy.context.view_layer.objects.active = obj
            STATE.update(phase="ahead", t=time.time())
            return 0.2
        if phase == "ahead":
            from wavg_blender import background

            read = background._READS.get(obj["wavg_key"])
            if (read is None or read.thread.is_alive()) and time.time() - STATE["t"] < 60:
                return 0.2
            check("making the mesh active reads its embedding ahead",
                  read is not None and read.result is not None,
                  f"(after {time.time() - STATE['t']:.1f} s)")
            from wavg_blender import decal_memo

            anchors = decal_anchors(obj)
            bpy.ops.wavg.decal_uv()
            # An anchor moved: once Blender is idle the decal is read ahead by the timer.
            group = obj.vertex_groups["wavg_anchors"]
            group.remove([anchors[0]])
            group.add([anchors[0] + 1], 1.0, 'REPLACE')
            bpy.context.view_layer.update()
            STATE.update(phase="decal", t=time.time(), ahead=decal_memo.COMPUTED_AHEAD[0])
            return 0.2
        if phase == "decal":
            from wavg_blender import decal_memo

            if decal_memo.COMPUTED_AHEAD[0] == STATE["ahead"] and time.time() - STATE["t"] < 60:
                return 0.2
            check("after an edit, the idle timer reads the decal ahead",
                  decal_memo.COMPUTED_AHEAD[0] == STATE["ahead"] + 1,
                  f"(after {time.time() - STATE['t']:.1f} s)")
            taken = decal_memo.TAKEN[0]
            bpy.ops.wavg.decal_uv()
            check("the click takes the decal read ahead", decal_memo.TAKEN[0] == taken + 1)
            finish()
    except Exception:
        traceback.print_exc()
        check("no exception", False)
        finish()
    return None


setup()
bpy.app.timers.register(step, first_interval=1.0)
