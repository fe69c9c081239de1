//! `cargo xtask dist`: every release artifact of one version in `target/dist/`, with a
//! `SHA256SUMS` file (docs/release.md says what goes where):
//! - `wavg-X.Y.Z-cp310-abi3-manylinux_2_28_x86_64.whl`: the Python wheel (release profile,
//!   stripped, linked for glibc 2.28 and checked by `auditwheel show`);
//! - `wavg-X.Y.Z.tar.gz`: the Python sdist (`pip install` builds it with a Rust toolchain);
//! - `wavg_blender-X.Y.Z-linux_x64.zip`: the Blender add-on, an extension for 4.2+ that
//!   also installs as a legacy add-on in 3.4-4.1, with that wheel unpacked in `vendor/`;
//! - `wavg-X.Y.Z-linux-x86_64.tar.gz`: the C/C++ prefix (`lib/libwavg.so.0` and its
//!   link, `lib/libwavg.a`, `include/wavg.h`, `include/wavg.hpp`, the CMake package, `wavg.pc`,
//!   the licences), from the CMake install with the tests and examples off;
//! - `crates/*.crate`: `cargo package --workspace` (each crate built from its package).

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::zig_env::Recorder;
use crate::{blender, python, steps, version};

/// The largest wheel a release ships (bytes).
const MAX_WHEEL: u64 = 15 * 1024 * 1024;
/// The oldest glibc the wheel supports, as a wheel platform tag.
pub const MANYLINUX: &str = "manylinux_2_28";
/// The target maturin's zig build compiles for (`--target`), which the C library shares.
const ZIG_TRIPLE: &str = "x86_64-unknown-linux-gnu";
/// The platform of the C tarball's name.
const PLATFORM: &str = "linux-x86_64";
/// The crates the release leaves out: automation, the lab, the fuzz targets, test and
/// build support (not published) and the Python extension's crate (shipped as the wheel).
pub const NOT_PACKAGED: &[&str] = &[
    "xtask",
    "wavg-lab",
    "wavg-fuzz",
    "wavg-py",
    "wavg-testdata",
    "wavg-hack",
];

/// The artifacts of one `dist` run.
pub struct Artifacts {
    /// The workspace version they carry.
    pub version: String,
    /// The abi3 wheel.
    pub wheel: PathBuf,
    /// The Python sdist.
    pub sdist: PathBuf,
    /// The Blender add-on / extension zip.
    pub blender_zip: PathBuf,
    /// The C/C++ tarball.
    pub c_tarball: PathBuf,
}

/// `target/dist/`.
pub fn dist_dir(root: &Path) -> PathBuf {
    steps::target_dir(root).join("dist")
}

/// Builds every artifact into an emptied `target/dist/` and writes `SHA256SUMS`, the crates
/// verified by `cargo package` beside the other builds.
pub fn run(root: &Path) -> Result<Artifacts, String> {
    run_with(root, || verify_crates(root))
}

/// [`run`] with the crates' verification done by `verified` (run beside the other builds;
/// it may wait for a verification started earlier); the `.crate` files it left are copied.
pub fn run_with(
    root: &Path,
    verified: impl FnOnce() -> Result<(), String> + Send,
) -> Result<Artifacts, String> {
    version::check(root)?;
    let version = version::workspace(root)?;
    let dist = dist_dir(root);
    if dist.exists() {
        std::fs::remove_dir_all(&dist).map_err(|e| format!("{}: {e}", dist.display()))?;
    }
    std::fs::create_dir_all(&dist).map_err(|e| format!("{}: {e}", dist.display()))?;
    let recorder = Recorder::new(root)?;
    // The crates' verification (a debug build in a target directory of its own) beside the
    // release builds: each leaves a core idle part of the time (about 40 s of a fresh
    // run's 390 s). The CPU figures printed inside overlap.
    let (built, packaged) = std::thread::scope(|scope| {
        let packaged = scope.spawn(|| {
            timed("crates", || {
                verified().and_then(|()| copy_crates(root, &dist))
            })
        });
        let built = (|| {
            let wheel = timed("wheel", || wheel(root, &dist, &version, &recorder))?;
            let sdist = timed("sdist", || sdist(root, &dist, &version))?;
            let blender_zip = dist.join(format!("wavg_blender-{version}-linux_x64.zip"));
            timed("Blender zip", || blender::pack(root, &wheel, &blender_zip))?;
            let zig_env = recorder.recorded()?;
            let c_tarball = timed("C tarball", || c_tarball(root, &dist, &version, &zig_env))?;
            Ok::<_, String>((wheel, sdist, blender_zip, c_tarball))
        })();
        let packaged = packaged
            .join()
            .unwrap_or_else(|_| Err("the crates' packaging panicked".into()));
        (built, packaged)
    });
    let (wheel, sdist, blender_zip, c_tarball) = built?;
    packaged?;
    checksums(&dist)?;
    eprintln!("==> {}: wavg {version}", dist.display());
    Ok(Artifacts {
        version,
        wheel,
        sdist,
        blender_zip,
        c_tarball,
    })
}

/// Runs one artifact's build and prints its wall and CPU time (the step table shows only
/// `dist`'s sum).
fn timed<T>(name: &str, build: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    let (t, cpu) = (std::time::Instant::now(), crate::cpu::now());
    let out = build()?;
    let cpu = crate::cpu::cell(crate::cpu::between(cpu, crate::cpu::now()));
    let wall = t.elapsed().as_secs_f64();
    eprintln!("    dist: {name} in {wall:.1} s ({cpu} CPU s)");
    Ok(out)
}

/// The one file in `dir` whose name starts with `prefix` and ends with `suffix`.
fn only_file(dir: &Path, prefix: &str, suffix: &str) -> Result<PathBuf, String> {
    let found: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .map(|n| n.to_string_lossy())
                .is_some_and(|n| n.starts_with(prefix) && n.ends_with(suffix))
        })
        .collect();
    match found.as_slice() {
        [one] => Ok(one.clone()),
        _ => Err(format!(
            "expected one {prefix}*{suffix} in {}, found {}",
            dir.display(),
            found.len()
        )),
    }
}

/// maturin in the test environment (`python/requirements-test.txt` pins it and zig, the
/// `ziglang` package), in the package's folder with cargo's target directory and the
/// environment's `bin/` first on `PATH` (where maturin finds zig).
fn maturin(root: &Path, args: &[&str]) -> Result<(), String> {
    maturin_env(root, args, None, &[])
}

/// [`maturin`] with `first` (a folder) put before the environment's `bin/` on `PATH`, and
/// extra variables.
fn maturin_env(
    root: &Path,
    args: &[&str],
    first: Option<&Path>,
    env: &[(&str, &str)],
) -> Result<(), String> {
    let py = python::ensure_venv(root)?;
    let bin = python::venv_dir(root).join("bin");
    let maturin = bin.join("maturin");
    let path = std::env::var_os("PATH").unwrap_or_default();
    let dirs = first.map(Path::to_path_buf).into_iter().chain([bin]);
    let path = std::env::join_paths(dirs.chain(std::env::split_paths(&path)))
        .map_err(|e| format!("PATH: {e}"))?;
    let target = steps::target_dir(root);
    let mut all = args.to_vec();
    let py_s = py.to_string_lossy();
    if args.first() == Some(&"build") {
        all.extend(["--interpreter", &py_s]);
    }
    let (target, path) = (target.to_string_lossy(), path.to_string_lossy());
    let mut vars = vec![("CARGO_TARGET_DIR", &*target), ("PATH", &*path)];
    vars.extend(env);
    steps::command_env(
        &root.join("python"),
        &maturin.to_string_lossy(),
        &all,
        &vars,
    )
}

/// The release wheel, linked by zig against glibc 2.28's symbols (this machine's linker
/// would use its own glibc's newer ones, which maturin refuses for the tag), tagged
/// [`MANYLINUX`] and checked again by `auditwheel show`; at most [`MAX_WHEEL`] bytes.
/// (`--target` and zig put this build in `target/x86_64-unknown-linux-gnu/release/`,
/// apart from the C library's.)
fn wheel(root: &Path, dist: &Path, version: &str, recorder: &Recorder) -> Result<PathBuf, String> {
    let out = dist.to_string_lossy();
    let vars = recorder.vars();
    let vars: Vec<(&str, &str)> = vars.iter().map(|(k, v)| (*k, v.as_str())).collect();
    maturin_env(
        root,
        &[
            "build",
            "--release",
            "--strip",
            "--zig",
            "--compatibility",
            MANYLINUX,
            "--out",
            &out,
        ],
        Some(recorder.dir()),
        &vars,
    )?;
    let wheel = only_file(dist, &format!("wavg-{version}-"), ".whl")?;
    let name = wheel.file_name().unwrap_or_default().to_string_lossy();
    let tag = format!("-cp310-abi3-{MANYLINUX}_x86_64.whl");
    if !name.ends_with(&tag) {
        return Err(format!("{name}: not tagged {tag}"));
    }
    let size = std::fs::metadata(&wheel)
        .map_err(|e| format!("{}: {e}", wheel.display()))?
        .len();
    if size > MAX_WHEEL {
        return Err(format!("{name}: {size} bytes, over {MAX_WHEEL}"));
    }
    auditwheel_show(root, &wheel)?;
    eprintln!("    {name}: {:.1} MB", size as f64 / 1e6);
    Ok(wheel)
}

/// `auditwheel show WHEEL` must find it consistent with [`MANYLINUX`].
fn auditwheel_show(root: &Path, wheel: &Path) -> Result<(), String> {
    let auditwheel = python::venv_dir(root).join("bin").join("auditwheel");
    let out = Command::new(&auditwheel)
        .arg("show")
        .arg(wheel)
        .output()
        .map_err(|e| format!("{}: {e}", auditwheel.display()))?;
    let text = String::from_utf8_lossy(&out.stdout).replace('\n', " ");
    let text = text.split_whitespace().collect::<Vec<_>>().join(" ");
    eprintln!("    auditwheel show: {text}");
    let expected = format!("consistent with the following platform tag: \"{MANYLINUX}_x86_64\"");
    if out.status.success() && text.contains(&expected) {
        Ok(())
    } else {
        Err(format!(
            "auditwheel show {}: not {MANYLINUX}: {text}",
            wheel.display()
        ))
    }
}

/// The sdist (maturin packs the workspace crates the extension depends on).
fn sdist(root: &Path, dist: &Path, version: &str) -> Result<PathBuf, String> {
    maturin(root, &["sdist", "--out", &dist.to_string_lossy()])?;
    only_file(dist, &format!("wavg-{version}"), ".tar.gz")
}

/// The C/C++ tarball: the CMake install (release library, tests and examples off) into a
/// staging prefix, without the separate debug info, packed with its top folder. The
/// library is built in `zig_env`, the wheel's environment (see [`crate::zig_env`]), for
/// the wheel's target and together with the wheel's crate (so that the dependencies have
/// the wheel's features: NumPy's turn on some of num-complex's): cargo compiles only
/// `wavg-ffi` and the unstripped `wavg-py`.
fn c_tarball(
    root: &Path,
    dist: &Path,
    version: &str,
    zig_env: &[(String, String)],
) -> Result<PathBuf, String> {
    crate::cbuild::ensure_packages()?;
    let target = steps::target_dir(root);
    let build = target.join("dist-cmake");
    let name = format!("wavg-{version}-{PLATFORM}");
    let stage = target.join("dist-stage");
    let prefix = stage.join(&name);
    for dir in [&build, &stage] {
        if dir.exists() {
            std::fs::remove_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
    }
    let (root_s, build_s) = (root.to_string_lossy(), build.to_string_lossy());
    steps::command(
        root,
        "cmake",
        &[
            "-S",
            &root_s,
            "-B",
            &build_s,
            "-DWAVG_BUILD_TESTS=OFF",
            "-DWAVG_BUILD_EXAMPLES=OFF",
            "-DWAVG_BUILD_HARNESS=OFF",
            "-DWAVG_CARGO_PROFILE=release",
            &format!("-DWAVG_CARGO_TARGET={ZIG_TRIPLE}"),
            "-DWAVG_CARGO_BUILD_ARGS=--package;wavg-ffi;--package;wavg-py",
            "-DCMAKE_INSTALL_LIBDIR=lib",
            &format!("-DWAVG_CARGO_TARGET_DIR={}", target.display()),
        ],
    )?;
    let args = ["--build", &build_s, "-j2"];
    eprintln!("    cmake {} (in the wheel's environment)", args.join(" "));
    let mut cmake = Command::new("cmake");
    cmake
        .args(args)
        .current_dir(root)
        .env_clear()
        .envs(zig_env.iter().map(|(k, v)| (k, v)));
    steps::run("cmake", &args, &mut cmake)?;
    steps::command(
        root,
        "cmake",
        &["--install", &build_s, "--prefix", &prefix.to_string_lossy()],
    )?;
    let debug = prefix.join("lib").join("libwavg.so.0.debug");
    std::fs::remove_file(&debug).map_err(|e| format!("{}: {e}", debug.display()))?;
    check_glibc(&prefix.join("lib").join("libwavg.so.0"))?;
    let tarball = dist.join(format!("{name}.tar.gz"));
    steps::command(
        root,
        "tar",
        &[
            "--sort=name",
            "--owner=0",
            "--group=0",
            "--numeric-owner",
            "-czf",
            &tarball.to_string_lossy(),
            "-C",
            &stage.to_string_lossy(),
            &name,
        ],
    )?;
    Ok(tarball)
}

/// The newest glibc symbol version `lib` needs (`objdump -T`) must be at most the wheel's
/// [`MANYLINUX`] glibc.
fn check_glibc(lib: &Path) -> Result<(), String> {
    let out = Command::new("objdump")
        .arg("-T")
        .arg(lib)
        .output()
        .map_err(|e| format!("objdump: {e}"))?;
    if !out.status.success() {
        return Err(format!("objdump -T {}: {}", lib.display(), out.status));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let newest = text
        .split("GLIBC_2.")
        .skip(1)
        .filter_map(|t| {
            let digits: String = t.chars().take_while(char::is_ascii_digit).collect();
            digits.parse::<u32>().ok()
        })
        .max()
        .ok_or_else(|| format!("{}: no glibc symbols", lib.display()))?;
    let limit: u32 = MANYLINUX
        .rsplit('_')
        .next()
        .and_then(|m| m.parse().ok())
        .ok_or("MANYLINUX names no glibc")?;
    eprintln!("    {}: newest symbol GLIBC_2.{newest}", lib.display());
    if newest > limit {
        return Err(format!(
            "{} needs GLIBC_2.{newest}, newer than {MANYLINUX}",
            lib.display()
        ));
    }
    Ok(())
}

/// `cargo package --workspace` (each package verified by building it alone), the `.crate`
/// files left in the `package-verify` target directory ([`copy_crates`] takes them). The
/// verification builds without debug info: whether a package builds does not depend on it,
/// and it costs compile and link time.
///
/// Cargo verifies a package against its workspace dependencies unpacked from their own
/// `.crate` files as if from a registry, and takes a registry crate of a name and version as
/// immutable: it keeps the sources unpacked by an earlier run and the artifacts compiled
/// from them. So the verification gets a target directory of its own, and both the
/// unpacked workspace crates and their artifacts there are removed first; otherwise a
/// crate using a new item of another would be verified against that crate's old source.
/// It also gets a cargo home of its own ([`crate::cargo_home`]), so that it runs beside the
/// test command's other cargo builds instead of taking turns with them.
pub fn verify_crates(root: &Path) -> Result<(), String> {
    let verify = verify_dir(root);
    let home = crate::cargo_home::beside(cargo_home().as_deref(), &verify.join("cargo-home"))?;
    forget_packaged(Some(&home), &verify)?;
    let home = home.to_string_lossy().into_owned();
    let verify_arg = verify.to_string_lossy().into_owned();
    let mut args = vec![
        "package",
        "--workspace",
        "--allow-dirty",
        "--config",
        "profile.dev.debug=0",
        "--target-dir",
        &verify_arg,
    ];
    for name in NOT_PACKAGED {
        args.extend(["--exclude", name]);
    }
    steps::command_env(root, "cargo", &args, &[("CARGO_HOME", &home)])
}

/// The target directory of the crates' verification.
fn verify_dir(root: &Path) -> PathBuf {
    steps::target_dir(root).join("package-verify")
}

/// Copies the `.crate` files of this version that [`verify_crates`] left into
/// `dist/crates/`.
fn copy_crates(root: &Path, dist: &Path) -> Result<(), String> {
    let from = verify_dir(root).join("package");
    let to = dist.join("crates");
    std::fs::create_dir_all(&to).map_err(|e| format!("{}: {e}", to.display()))?;
    let version = version::workspace(root)?;
    let mut count = 0;
    for entry in std::fs::read_dir(&from).map_err(|e| format!("{}: {e}", from.display()))? {
        let path = entry.map_err(|e| e.to_string())?.path();
        let name = path
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        if name.ends_with(&format!("-{version}.crate")) {
            std::fs::copy(&path, to.join(&name)).map_err(|e| format!("{name}: {e}"))?;
            count += 1;
        }
    }
    if count == 0 {
        return Err(format!(
            "no crates of version {version} in {}: did the verification run?",
            from.display()
        ));
    }
    eprintln!("    {count} crates in {}", to.display());
    Ok(())
}

/// Cargo's home: `$CARGO_HOME`, else `~/.cargo`.
fn cargo_home() -> Option<PathBuf> {
    std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")))
}

/// Removes what an earlier `cargo package` left of the workspace's own crates: their
/// sources unpacked under cargo's home `home` (in the local registries, whose folder names
/// start with `-`) and everything compiled from them in the verification's target
/// directory `verify`. Crates from crates.io and their artifacts stay.
fn forget_packaged(home: Option<&Path>, verify: &Path) -> Result<(), String> {
    let mut doomed = Vec::new();
    if let Some(src) = home.map(|h| h.join("registry").join("src")) {
        for registry in entries(&src) {
            if file_name(&registry).starts_with('-') {
                doomed.extend(entries(&registry));
            }
        }
    }
    for sub in [".fingerprint", "deps", "build", "incremental"] {
        doomed.extend(entries(&verify.join("debug").join(sub)));
    }
    doomed.extend(entries(&verify.join("package")));
    for path in doomed {
        let name = file_name(&path);
        if !(name.starts_with("wavg") || name.starts_with("libwavg")) {
            continue;
        }
        let removed = if path.is_dir() {
            std::fs::remove_dir_all(&path)
        } else {
            std::fs::remove_file(&path)
        };
        removed.map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}

/// The entries of `dir`; none when it does not exist or cannot be read.
fn entries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .map(|it| it.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default()
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .unwrap_or_default()
        .to_string_lossy()
        .into_owned()
}

/// `SHA256SUMS` of every file under `dist` (paths relative to it), as `sha256sum -c` reads.
fn checksums(dist: &Path) -> Result<(), String> {
    let mut files = Vec::new();
    list_files(dist, dist, &mut files)?;
    files.sort();
    let out = Command::new("sha256sum")
        .args(&files)
        .current_dir(dist)
        .output()
        .map_err(|e| format!("sha256sum: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "sha256sum: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let sums = dist.join("SHA256SUMS");
    std::fs::write(&sums, &out.stdout).map_err(|e| format!("{}: {e}", sums.display()))
}

fn list_files(base: &Path, dir: &Path, out: &mut Vec<String>) -> Result<(), String> {
    for entry in std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))? {
        let path = entry.map_err(|e| e.to_string())?.path();
        if path.is_dir() {
            list_files(base, &path, out)?;
        } else if let Ok(rel) = path.strip_prefix(base) {
            out.push(rel.to_string_lossy().into_owned());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_workspace_crates_left_by_packaging_are_forgotten() {
        let dir = std::env::temp_dir().join(format!("wavg-forget-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let (home, verify) = (dir.join("home"), dir.join("verify"));
        let made = [
            "home/registry/src/-0123/wavg-0.1.0/src/lib.rs",
            "home/registry/src/-0123/wavg-mesh-0.1.0/Cargo.toml",
            "home/registry/src/index.crates.io-99/wavg-other-1.0.0/Cargo.toml",
            "home/registry/src/index.crates.io-99/faer-0.22.0/Cargo.toml",
            "verify/debug/.fingerprint/wavg-mesh-abc/lib-wavg_mesh",
            "verify/debug/.fingerprint/faer-abc/lib-faer",
            "verify/debug/deps/libwavg_mesh-abc.rlib",
            "verify/debug/deps/libfaer-abc.rlib",
            "verify/debug/build/wavg-ffi-abc/output",
            "verify/package/wavg-0.1.0.crate",
        ];
        for file in made {
            let path = dir.join(file);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, "x").unwrap();
        }
        forget_packaged(Some(&home), &verify).unwrap();
        let kept: Vec<_> = made.iter().filter(|f| dir.join(f).exists()).collect();
        assert_eq!(
            kept,
            [
                &"home/registry/src/index.crates.io-99/wavg-other-1.0.0/Cargo.toml",
                &"home/registry/src/index.crates.io-99/faer-0.22.0/Cargo.toml",
                &"verify/debug/.fingerprint/faer-abc/lib-faer",
                &"verify/debug/deps/libfaer-abc.rlib",
            ]
        );
        // Nothing to forget, or no cargo home at all, is fine.
        forget_packaged(None, &dir.join("missing")).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A two-crate workspace packaged twice by the real cargo (offline, a cargo home of
    /// its own), `wavg-toyb` using an item `wavg-toya` gained in between: cargo verifies
    /// against the stale registry copy unless [`forget_packaged`] ran.
    #[test]
    fn a_changed_crate_is_verified_against_its_new_source() {
        let dir = std::env::temp_dir().join(format!("wavg-package-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let (ws, home, target) = (dir.join("ws"), dir.join("home"), dir.join("target"));
        let write = |file: &str, text: &str| {
            let path = ws.join(file);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, text).unwrap();
        };
        let manifest = "[workspace]\nmembers = [\"a\", \"b\"]\nresolver = \"3\"\n\n\
                        [profile.dev]\nopt-level = 1\n";
        write("Cargo.toml", manifest);
        let package = |name: &str, deps: &str| {
            format!(
                "[package]\nname = \"{name}\"\nversion = \"0.1.0\"\nedition = \"2024\"\n\
                 license = \"MIT\"\ndescription = \"test\"\n\n[dependencies]\n{deps}"
            )
        };
        write("a/Cargo.toml", &package("wavg-toya", ""));
        let dep = "wavg-toya = { path = \"../a\", version = \"0.1.0\" }\n";
        write("b/Cargo.toml", &package("wavg-toyb", dep));
        write("a/src/lib.rs", "pub fn one() -> u32 { 1 }\n");
        write("b/src/lib.rs", "pub fn f() -> u32 { wavg_toya::one() }\n");
        let package = || {
            let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
            std::process::Command::new(cargo)
                .args([
                    "package",
                    "--offline",
                    "--workspace",
                    "--allow-dirty",
                    "--quiet",
                ])
                .args(["--config", "profile.dev.debug=0"])
                .arg("--target-dir")
                .arg(&target)
                .current_dir(&ws)
                .env("CARGO_HOME", &home)
                .env_remove("CARGO_TARGET_DIR")
                .output()
                .unwrap()
        };
        let first = package();
        assert!(
            first.status.success(),
            "{}",
            String::from_utf8_lossy(&first.stderr)
        );
        write(
            "a/src/lib.rs",
            "pub fn one() -> u32 { 1 }\npub fn two() -> u32 { 2 }\n",
        );
        write("b/src/lib.rs", "pub fn f() -> u32 { wavg_toya::two() }\n");
        assert!(!package().status.success(), "the stale copy was not used");
        forget_packaged(Some(&home), &target).unwrap();
        let again = package();
        assert!(
            again.status.success(),
            "{}",
            String::from_utf8_lossy(&again.stderr)
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
