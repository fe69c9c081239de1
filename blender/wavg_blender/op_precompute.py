"""``wavg.precompute``: the embedding of the active mesh, through the embedding cache
every way into wavg shares (read from it when an entry exists, else computed and stored).

From the UI it runs in a worker thread while a modal timer shows the progress in the status
bar; Esc makes the progress callback return ``False``, which cancels wavg's precomputation
(nothing is written: the cache stores only finished embeddings). From a script (``execute``, also in background mode) it runs in
place, reporting progress to the window manager."""

import threading

import bpy

from . import surfaces
from .common import active_mesh, guarded
from .errors import AddonError, describe
from .meshdata import MeshInput


class _Job:
    """One precomputation: the surface, its progress and its outcome."""

    def __init__(self, obj, landmarks, seed):
        self.mesh = MeshInput(obj)
        self.surface = surfaces.new_surface(self.mesh)
        self.landmarks, self.seed = surfaces.landmarks_arg(landmarks), int(seed)
        # Decided here, on Blender's thread: the worker must not read bpy.data.
        self.folder = surfaces.write_dir()
        self.report = None
        self.stage, self.done, self.total = "starting", 0, 1
        self.cancel = False
        self.error = None
        self.listener = None

    def progress(self, stage, done, total):
        """wavg's progress callback: records the state; ``False`` cancels."""
        self.stage, self.done, self.total = str(stage), int(done), max(int(total), 1)
        if self.listener is not None:
            self.listener(self)
        return not self.cancel

    def run(self):
        """Precomputes; an error (or the cancellation) is kept in ``self.error``."""
        try:
            self.report = self.surface.precompute(
                landmarks=self.landmarks,
                seed=self.seed,
                progress=self.progress,
                cache=self.folder if self.folder is not None else False,
            )
        except BaseException as e:  # noqa: BLE001 (cancellation may be KeyboardInterrupt)
            self.error = e

    def status(self):
        pct = 100.0 * self.done / self.total
        return f"wavg precompute '{self.mesh.name}': {self.stage} {pct:.0f}% (Esc cancels)"

    def finish(self, obj):
        """Keeps the embedding (the cache entry was written by ``precompute``) and records
        its options on ``obj``; returns the entry's path (``None`` without a cache folder).
        Raises :class:`AddonError` on any failure."""
        if self.cancel:
            raise AddonError("precompute cancelled; nothing was written")
        if self.error is not None:
            raise AddonError(f"precompute of '{self.mesh.name}' failed: {describe(self.error)}")
        path = (self.report or {}).get("cache_path")
        if self.folder is not None and path is None:
            raise AddonError(
                f"cannot write the embedding of '{self.mesh.name}' to the cache {self.folder}"
            )
        surfaces.remember(self.mesh.key, self.surface)
        surfaces.remember_options(obj, self.landmarks, self.seed, path)
        obj["wavg_key"] = self.mesh.key
        return path


class WAVG_OT_precompute(bpy.types.Operator):
    """Compute the embedding of the active mesh (needed by every other wavg operator) and
    cache it beside the .blend file or in wavg's user cache"""

    bl_idname = "wavg.precompute"
    bl_label = "Precompute Embedding"
    bl_options = {'REGISTER', 'UNDO'}

    landmarks: bpy.props.IntProperty(
        name="Landmarks",
        default=0,
        min=0,
        description="Landmark vertices of the embedding (0: the library's choice, the one "
        "every way into wavg makes)",
    )
    seed: bpy.props.IntProperty(name="Seed", default=0, min=0, description="Random seed")

    @classmethod
    def poll(cls, context):
        obj = context.view_layer.objects.active
        return obj is not None and obj.type == 'MESH'

    def execute(self, context):
        def step():
            obj = active_mesh(context)
            job = _Job(obj, self.landmarks, self.seed)
            wm = context.window_manager
            wm.progress_begin(0, 1000)

            job.listener = lambda j: wm.progress_update(int(1000 * j.done / j.total))
            try:
                job.run()
            finally:
                wm.progress_end()
            path = job.finish(obj)
            self.report({'INFO'}, f"embedding of '{obj.name}' cached in {path}")
            return {'FINISHED'}

        return guarded(self, step)

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)

        def start():
            self._obj = active_mesh(context)
            self._job = _Job(self._obj, self.landmarks, self.seed)
            self._thread = threading.Thread(target=self._job.run, daemon=True)
            self._thread.start()
            wm = context.window_manager
            self._timer = wm.event_timer_add(0.1, window=context.window)
            wm.progress_begin(0, 1000)
            wm.modal_handler_add(self)
            return {'RUNNING_MODAL'}

        return guarded(self, start)

    def modal(self, context, event):
        job = self._job
        if event.type == 'ESC':
            job.cancel = True
            return {'RUNNING_MODAL'}
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        wm = context.window_manager
        wm.progress_update(int(1000 * job.done / job.total))
        if context.workspace is not None:
            context.workspace.status_text_set(job.status())
        if self._thread.is_alive():
            return {'RUNNING_MODAL'}
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)

        def end():
            path = job.finish(self._obj)
            self.report({'INFO'}, f"embedding of '{self._obj.name}' cached in {path}")
            return {'FINISHED'}

        return guarded(self, end)
