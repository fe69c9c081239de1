//! Build and test automation: `cargo xtask test` runs every check the project has, in the
//! order CI runs them, and tells you exactly what to install when a tool is missing.

#![forbid(unsafe_code)]

mod beside;
mod blender;
mod cargo_home;
mod cbuild;
mod cli_docs;
mod cpu;
mod dist;
mod examples;
mod features;
mod fuzz;
mod gltf;
mod installed;
mod lab;
mod lines;
mod man;
mod map;
mod parallel;
mod policy;
mod prefetch;
mod python;
mod sancov;
mod sandbox;
mod steps;
mod system;
mod version;
mod web;
mod zig_env;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use beside::Beside;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if std::env::var_os(sancov::ENV).is_some() {
        return sancov::wrap(&args);
    }
    match args.first().map(String::as_str) {
        Some("test") => match args.get(1).map(String::as_str) {
            None => run_all(&workspace_root(), false),
            Some("--quick") => run_all(&workspace_root(), true),
            Some(_) => usage(),
        },
        Some("fuzz") => match fuzz_args(&args[1..]) {
            Some((seconds, target)) => {
                report(fuzz::run(&workspace_root(), seconds, target.as_deref()))
            }
            None => usage(),
        },
        Some("lines") => report(lines::run(&workspace_root())),
        Some("lab") => report(lab::run(&workspace_root(), &args[1..])),
        Some("man") if args.len() <= 2 => {
            report(man::run(&workspace_root(), args.get(1).map(String::as_str)))
        }
        Some("cli-docs") if args.len() == 1 => report(cli_docs::run(&workspace_root())),
        Some("blender-addon") if args.len() == 1 => {
            report(blender::build_addon(&workspace_root()).map(|zip| println!("{}", zip.display())))
        }
        Some("blender") if args.len() == 1 => report(blender::test(&workspace_root())),
        Some("web") => match args.get(1).map(String::as_str) {
            None => report(web::build(&workspace_root())),
            Some("--check") => report(web::check_assets(&workspace_root())),
            Some(_) => usage(),
        },
        Some("gltf-validate") if args.len() == 1 => report(gltf::validate(&workspace_root())),
        Some("dist") => match args.get(1).map(String::as_str) {
            None => report(dist::run(&workspace_root()).map(|_| ())),
            Some("--crates") if args.len() == 2 => report(dist::verify_crates(&workspace_root())),
            Some("--installed") => {
                let root = workspace_root();
                let data_dir = report_data_dir(&root);
                let mut log = steps::Log::default();
                let ok = release(&root, &data_dir, &mut log, None);
                log.print_table();
                if ok {
                    ExitCode::SUCCESS
                } else {
                    ExitCode::FAILURE
                }
            }
            Some(_) => usage(),
        },
        Some("venv") if args.len() == 1 => {
            report(python::ensure_venv(&workspace_root()).map(|py| println!("{}", py.display())))
        }
        Some("wheel") if args.len() == 1 => {
            report(python::build_wheel(&workspace_root()).map(|w| println!("{}", w.display())))
        }
        _ => usage(),
    }
}

fn usage() -> ExitCode {
    eprintln!(
        "usage: cargo xtask test [--quick] | cargo xtask fuzz [--seconds N] [--target NAME] | \
         cargo xtask lab [NAME ARGS] | cargo xtask lines | cargo xtask man [DIR] | cargo xtask cli-docs | cargo xtask venv | cargo xtask wheel | cargo xtask dist [--installed | --crates] | \
         cargo xtask blender-addon | cargo xtask blender | cargo xtask web [--check] | cargo xtask gltf-validate\n\n  \
         test   every check, in CI's order (the steps: docs/development.md), then a table of \
         step times\n  \
         test --quick   rustfmt check, clippy and the unit tests, for the edit loop\n  \
         fuzz   every fuzz target (or only NAME) for N seconds (default 60) each\n  \
         lab    build the lab (lab/, not a default member), or run its program NAME \
         (lab/src/bin/NAME.rs, release mode) with ARGS\n  \
         lines  the Rust files over {MAX} lines of non-test code (before the first #[cfg(test)])\n  \
         man    man pages of wavg and every subcommand into DIR (default target/man)\n  \
         cli-docs   write docs/cli.md from the command definitions (help texts and examples)\n  \
         venv   make or update the test virtual environment (target/py-venv, from python/requirements-test.txt) and print its interpreter\n  \
         wheel  build the Python wheel (maturin, dev profile, target/wheels) and print its path\n  \
         dist   every release artifact (wheel, sdist, Blender zip, C tarball, crates) into target/dist/ with SHA256SUMS (docs/release.md); --installed: then the release steps of `test` (each artifact installed and used); --crates: only the crates' verification (cargo package --workspace, into target/package-verify)\n  \
         blender-addon   build the Blender add-on target/wavg_blender.zip (the wavg wheel unpacked in its vendor/ folder)\n  \
         blender   the blender step of `test` alone: the add-on's tests in Blender, with a temporary home holding a decoy add-on\n  \
         web    vendor three.js for the page of `wavg serve` into web/vendor/three by npm ci of web/package-lock.json (--check: verify the checked-in files)\n  \
         gltf-validate   the Khronos glTF Validator over the glTF files the last `test` run's tests wrote (target/gltf-written)",
        MAX = lines::MAX_LINES
    );
    ExitCode::from(2)
}

/// Seconds each fuzz target runs within `cargo xtask test`.
const SMOKE_SECONDS: u64 = 10;

/// `[--seconds N] [--target NAME]` in any order: seconds (default 60) and target.
fn fuzz_args(args: &[String]) -> Option<(u64, Option<String>)> {
    let (mut seconds, mut target) = (60, None);
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let value = it.next()?;
        match flag.as_str() {
            "--seconds" => seconds = value.parse().ok()?,
            "--target" if fuzz::TARGETS.contains(&value.as_str()) => target = Some(value.clone()),
            _ => return None,
        }
    }
    Some((seconds, target))
}

fn report(result: Result<(), String>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprintln!("xtask: {msg}");
            ExitCode::FAILURE
        }
    }
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

/// `cargo xtask test [--quick]`: every check in CI's order, or with `--quick` the edit
/// loop's (format, clippy, unit tests); a table of step times at the end either way.
fn run_all(root: &Path, quick: bool) -> ExitCode {
    if let Err(msg) = check_tools() {
        eprintln!("xtask: {msg}");
        return ExitCode::FAILURE;
    }
    let data_dir = report_data_dir(root);
    let mut log = steps::Log::default();
    let ok = run_checks(root, &data_dir, quick, &mut log);
    log.print_table();
    if ok {
        eprintln!("==> all checks passed");
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

/// The checks, stopping at the first failure. One optimised dev build serves the tests, the
/// examples, the C library and the fuzz seeds.
fn run_checks(root: &Path, data_dir: &Path, quick: bool, log: &mut steps::Log) -> bool {
    // Debian packages of later steps, installed while the first ones compile (joined when
    // this returns).
    let _packages = (!quick).then(|| prefetch::start(root));
    let cargo = |args: &[&str]| steps::command(root, "cargo", args);
    let ok = log.run("format", || cargo(&["fmt", "--all", "--check"]))
        && log.run("clippy", || {
            steps::cargo_workspace(
                root,
                &["clippy", "--all-targets"],
                &["--", "-D", "warnings"],
            )
        });
    if !ok {
        return false;
    }
    if quick {
        return log.run("unit tests", || {
            steps::cargo_workspace(root, &["test", "--lib"], &[])
        });
    }
    // The crates' verification beside the steps from the tests on, at the lowest priority
    // ([`Beside::start_idle`]): the tests' runs and the Python, Blender, browser and C steps
    // wait on one process much of the time, and it takes the idle core. `dist` waits for
    // it; when a step fails first, it is dropped unwaited, which stops it.
    let name =
        "crates' verification (cargo package --workspace; beside the steps from the tests on)";
    let crates = match Beside::start_idle(root, name, "crates-verify", &["dist", "--crates"]) {
        Ok(c) => c,
        Err(e) => return log.record(name, 0.0, None, Err(e)),
    };
    build_and_use(root, data_dir, log) && release_and_fuzz(root, data_dir, log, Some(crates))
}

/// The steps from the tests to ctest: the everyday build and its tests, then each way in
/// (Python, Blender, the browser, C/C++) used from it.
fn build_and_use(root: &Path, data_dir: &Path, log: &mut steps::Log) -> bool {
    log.run("tests (unit, integration, doc; examples built)", || {
        let gltf_dir = gltf::clear(root)?;
        let gltf_dir = gltf_dir.to_string_lossy();
        steps::cargo_workspace_env(root, &["test"], &[], &[(gltf::DIR_VAR, &gltf_dir)])
    }) && log.run(
        &format!(
            "source policy (files over {} lines, forbid(unsafe_code), module style, one test binary per crate, the map, one version, one build of each dependency)",
            lines::MAX_LINES
        ),
        || {
            lines::run(root)
                .and_then(|()| policy::check_unsafe(root))
                .and_then(|()| policy::check_module_style(root))
                .and_then(|()| policy::check_test_binaries(root))
                .and_then(|()| map::check(root))
                .and_then(|()| version::check(root))
                .and_then(|()| features::check(root))
        },
    ) && log.run("docs (cargo doc, warnings as errors)", || {
        steps::command_env(
            root,
            "cargo",
            &[&["doc", "--workspace"], steps::EXCLUDED, &["--no-deps"]].concat(),
            &[("RUSTDOCFLAGS", "-D warnings")],
        )
    }) && log.run("examples", || examples::run(root))
        && log.run("python environment", || {
            python::ensure_venv(root).map(|_| ())
        })
        && log.run("python package (wheel, pytest python/tests)", || {
            python::test_package(root, data_dir)
        })
        && log.run("python blocks of README.md and docs/", || {
            python::docs_blocks(root, data_dir)
        })
        && log.run("blender", || blender::test(root))
        && log.run("web assets", || web::check_assets(root))
        && log.run("glTF validator (every .glb/.gltf the tests wrote)", || {
            gltf::validate(root)
        })
        && log.run("browser tests", || web::browser_tests(root, data_dir))
        && log.run("C/C++ packages", cbuild::ensure_packages)
        && cbuild::steps(root, data_dir)
            .into_iter()
            .all(|(name, program, args)| {
                let args: Vec<&str> = args.iter().map(String::as_str).collect();
                log.run(name, || steps::command(root, &program, &args))
            })
}

/// [`release`] with the fuzz targets' build and smoke run beside it ([`beside`]): nothing
/// after ctest builds into the dev profile's folder, where the instrumented targets go.
fn release_and_fuzz(
    root: &Path,
    data_dir: &Path,
    log: &mut steps::Log,
    crates: Option<Beside>,
) -> bool {
    let seconds = SMOKE_SECONDS.to_string();
    let name = format!(
        "fuzz build and smoke ({} targets x {SMOKE_SECONDS} s; beside the release steps)",
        fuzz::TARGETS.len()
    );
    let fuzz = match Beside::start(root, &name, "fuzz-smoke", &["fuzz", "--seconds", &seconds]) {
        Ok(f) => f,
        Err(e) => {
            if let Some(c) = crates {
                c.cancel();
            }
            return log.record(&name, 0.0, None, Err(e));
        }
    };
    if release(root, data_dir, log, crates) {
        fuzz.finish(log)
    } else {
        fuzz.cancel();
        false
    }
}

/// `cargo xtask dist`, then each artifact installed and used as its users do. With
/// `crates`, the crates' verification already running beside, dist waits for it instead of
/// running its own.
fn release(root: &Path, data_dir: &Path, log: &mut steps::Log, crates: Option<Beside>) -> bool {
    let mut built = None;
    let mut lane = None;
    let dist_ok = log.run("release artifacts (cargo xtask dist)", || {
        built = Some(match crates {
            None => dist::run(root)?,
            Some(c) => dist::run_with(root, || {
                let finished = c.wait();
                let result = finished.result.clone();
                lane = Some(finished);
                result.map_err(|e| format!("the crates' verification failed: {e}"))
            })?,
        });
        Ok(())
    });
    let lane_ok = lane.is_none_or(|f| f.record(log));
    if !(dist_ok && lane_ok) {
        return false;
    }
    let Some(a) = built else { return false };
    log.run(
        "installed: wheel, CPython 3.10-3.13, NumPy 1.x/2.x, no Rust",
        || installed::wheels(root, data_dir, &a),
    ) && log.run("installed: sdist (pip with Rust)", || {
        installed::sdist(root, &a)
    }) && log.run("installed: C tarball (CMake, pkg-config)", || {
        installed::c_tarball(root, data_dir, &a)
    }) && log.run("installed: Blender 4.2/4.5/5.0 extension (bpy)", || {
        installed::blender(root, &a)
    })
}

/// rustfmt and clippy ship as rustup components; they cannot be downloaded from here, so
/// say exactly what is missing and how to add it.
fn check_tools() -> Result<(), String> {
    for (tool, component) in [("rustfmt", "rustfmt"), ("cargo-clippy", "clippy")] {
        let ok = Command::new(tool)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success());
        if !ok {
            return Err(format!(
                "{tool} is missing: install it with `rustup component add {component}`"
            ));
        }
    }
    Ok(())
}

/// Prints which test-data folder the tests will read, and returns it.
fn report_data_dir(root: &Path) -> PathBuf {
    let dir = std::env::var_os("WAVG_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("../shared/data"));
    if dir.is_dir() {
        eprintln!("==> test data: {}", dir.display());
    } else {
        eprintln!(
            "==> test data: {} not found; tests that need real meshes will say SKIPPED \
             (set WAVG_DATA_DIR to the shared data folder to run them)",
            dir.display()
        );
    }
    dir
}
