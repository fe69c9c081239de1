"""Headless tests of the wavg Blender add-on, run inside Blender:

    blender -b --factory-startup --python-exit-code 1 --python blender/tests/run.py -- \\
        --zip target/wavg_blender.zip [--wavg-cli target/debug/wavg] [--bench | --bench-only]

Installs the add-on from the zip (into a temporary script folder), builds meshes in code,
runs every operator as a script would (active object, selected objects, selection order)
and checks the results against the wavg package the add-on ships (and `wavg decal` when
the CLI is given); undo; every bad input. `--bench` also measures the latency of every
operator and live update on a 25k-vertex mesh (`bench.py`; printed, not asserted). Exits 1
on the first failed check.
"""

import argparse
import os
import shutil
import sys
import tempfile
import traceback

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import cases  # noqa: E402
import cases_decal  # noqa: E402
import cases_more  # noqa: E402
import scene  # noqa: E402


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="run.py")
    p.add_argument("--zip", required=True, help="the add-on zip (cargo xtask blender-addon)")
    p.add_argument("--wavg-cli", help="the wavg command line, to compare the decal with")
    p.add_argument("--bench", action="store_true", help="also measure (50k-face mesh)")
    p.add_argument("--bench-only", action="store_true", help="measure only (no checks)")
    p.add_argument(
        "--extension", action="store_true",
        help="install as a Blender 4.2+ extension (Install from Disk) instead of a legacy add-on",
    )
    return p.parse_args(argv)


def install(zip_path, tmp, extension):
    """Installs and enables the add-on from the zip: as a legacy add-on into a temporary
    script folder, or as a 4.2+ extension into the user repository."""
    zip_path = os.path.abspath(zip_path)
    if extension:
        bpy.ops.extensions.package_install_files(
            filepath=zip_path, repo="user_default", enable_on_install=True
        )
        name = "bl_ext.user_default.wavg_blender"
        root = bpy.utils.user_resource('EXTENSIONS')
    else:
        root = os.path.join(tmp, "scripts")
        os.makedirs(os.path.join(root, "addons"), exist_ok=True)
        bpy.context.preferences.filepaths.script_directory = root
        bpy.utils.refresh_script_paths()
        bpy.ops.preferences.addon_install(filepath=zip_path, target='PREFS')
        bpy.ops.preferences.addon_enable(module="wavg_blender")
        name = "wavg_blender"
    addon = sys.modules[name]
    sys.modules["wavg_blender"] = addon  # the tests import it by this name
    path = os.path.dirname(addon.__file__)
    assert path.startswith(root), f"the add-on was loaded from {path}, not from the zip"
    import wavg

    assert os.path.dirname(wavg.__file__).startswith(path), (
        f"wavg was imported from {wavg.__file__}, not from the add-on's vendor folder"
    )
    print(f"add-on from {path}; wavg {getattr(wavg, '__version__', '?')} from {wavg.__file__}")


def main():
    args = parse_args()
    tmp = tempfile.mkdtemp(prefix="wavg-blender-tests-")
    try:
        run(args, tmp)
    finally:
        # The installed add-on, its cache and the tests' files go with the run, unless kept
        # for a look after a failure.
        if os.environ.get("WAVG_KEEP_TEST_FILES"):
            print(f"test files kept in {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)


def run(args, tmp):
    os.environ["WAVG_BLENDER_CACHE"] = os.path.join(tmp, "cache")
    install(args.zip, tmp, args.extension)
    ctx = cases.Context(tmp=tmp, cli=args.wavg_cli)
    tests = [] if args.bench_only else cases.TESTS + cases_more.TESTS + cases_decal.TESTS
    if args.bench or args.bench_only:
        import bench

        tests += bench.TESTS
    failed = []
    for test in tests:
        scene.clear()
        bpy.ops.ed.undo_push(message="start")
        try:
            test(ctx)
            print(f"ok     {test.__name__}")
        except Exception:
            traceback.print_exc()
            print(f"FAILED {test.__name__}")
            failed.append(test.__name__)
    print(f"{len(tests) - len(failed)} passed, {len(failed)} failed")
    if failed:
        raise SystemExit(f"failed: {', '.join(failed)}")

main()
