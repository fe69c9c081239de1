//! Helpers shared by the subcommands: loading a mesh from a file or a builtin name, and
//! validating it with a message that says what is wrong and how to repair it.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use wavg::{MeshError, TriMesh, ValidMesh};

use crate::CliError;
use crate::error::Context;

/// Prefix that names a procedural mesh instead of a file, e.g. `builtin:torus`.
pub use wavg::BUILTIN_PREFIX;

/// Loads `builtin:NAME` (see `wavg info --builtin`) or a mesh file ([`wavg::load_mesh`]).
/// Unreadable or unparseable input is a [`CliError::input`] (exit status 2) whose one-line
/// message names the file and, for parse errors, the line.
pub fn load_mesh(path_or_builtin: &str) -> Result<TriMesh, CliError> {
    Ok(wavg::load_mesh(path_or_builtin)?)
}

/// Like [`load_mesh`], also returning what the file held beyond the triangle mesh
/// ([`wavg::LoadNotes`]; default for builtins).
pub fn load_mesh_notes(path_or_builtin: &str) -> Result<(TriMesh, wavg::LoadNotes), CliError> {
    Ok(wavg::load_mesh_with_notes(path_or_builtin)?)
}

/// Loads and validates a mesh. When validation fails, the problems (counts and first
/// offending indices) are printed to stderr with a hint, and the error is returned
/// (exit status 2: the input is not usable).
#[allow(dead_code)] // for precompute/forward/inverse
pub fn load_valid(path_or_builtin: &str) -> Result<Arc<ValidMesh>, CliError> {
    let t = Instant::now();
    let mesh = load_mesh(path_or_builtin)?;
    step("read + parse the mesh", t);
    validate(path_or_builtin, mesh)
}

/// The validation half of [`load_valid`], for a mesh already read from `path_or_builtin`.
pub fn validate(path_or_builtin: &str, mesh: TriMesh) -> Result<Arc<ValidMesh>, CliError> {
    let t = Instant::now();
    match ValidMesh::new(mesh) {
        Ok(m) => {
            step("validate + topology", t);
            Ok(Arc::new(m))
        }
        Err(MeshError::Invalid(report)) => {
            let n = report.problems.len();
            eprintln!("{path_or_builtin}: the mesh is not a valid oriented manifold:");
            for line in report.lines() {
                eprintln!("  {line}");
            }
            eprintln!(
                "hint: run `wavg info {path_or_builtin}` for details; duplicate vertices, \
                 degenerate/duplicate faces, unreferenced vertices and extra components can \
                 be removed with `wavg repair {path_or_builtin} -o FIXED.obj [--largest-component]`"
            );
            let e = CliError::from(MeshError::Invalid(report));
            Err(e.with_message(format!(
                "{path_or_builtin}: invalid mesh ({n} problem{})",
                if n == 1 { "" } else { "s" }
            )))
        }
        Err(e) => Err(e.into()),
    }
}

/// A per-sample solver error as the one-line reason of a `none` output line.
pub fn reason(e: &wavg::SolveError) -> String {
    wavg::lines::reason(e)
}

/// With `WAVG_STEP_TIMES` set (to anything), prints `step NAME MS` on stderr, the
/// milliseconds since `since`, and returns now: where a command's start-up time goes
/// (BENCHMARKS.md).
pub fn step(name: &str, since: Instant) -> Instant {
    let now = Instant::now();
    if std::env::var_os("WAVG_STEP_TIMES").is_some() {
        eprintln!("step {name} {:.1}", (now - since).as_secs_f64() * 1e3);
    }
    now
}

/// CPU time consumed so far by the calling thread (`thread`) or by the whole process (all
/// threads), in seconds, from the POSIX CPU-time clocks (nanosecond resolution, unlike
/// tick-based counters). `None` where they are unavailable.
pub fn cpu_seconds(thread: bool) -> Option<f64> {
    #[cfg(unix)]
    {
        use nix::time::{ClockId, clock_gettime};
        let id = if thread {
            ClockId::CLOCK_THREAD_CPUTIME_ID
        } else {
            ClockId::CLOCK_PROCESS_CPUTIME_ID
        };
        let ts = clock_gettime(id).ok()?;
        Some(ts.tv_sec() as f64 + ts.tv_nsec() as f64 * 1e-9)
    }
    #[cfg(not(unix))]
    {
        let _ = thread;
        None
    }
}

/// The largest `--threads` accepted: the library's [`wavg::Par::max_threads`].
pub fn max_threads() -> usize {
    wavg::Par::max_threads()
}

/// Parses a `--threads` value: an integer from 1 to [`max_threads`].
pub fn parse_threads(s: &str) -> Result<usize, String> {
    let n: usize = s
        .parse()
        .map_err(|_| format!("'{s}' is not a whole number of threads"))?;
    let max = max_threads();
    if n == 0 {
        return Err("at least 1 thread is needed".into());
    }
    if n > max {
        return Err(format!(
            "{n} threads is more than {max}, the limit on this machine (4 per CPU, at least \
             64): more threads than cores only add overhead"
        ));
    }
    Ok(n)
}

/// The most samples or queries one command takes (each costs tens to hundreds of bytes, so
/// this stays within a few gigabytes; more is better done in several runs).
pub const MAX_COUNT: usize = 10_000_000;

/// The most frames `morph` writes or `remesh` times.
pub const MAX_FRAMES: usize = 100_000;

/// A whole number from 0 to `max`, `what` naming it in the error.
fn parse_up_to(s: &str, max: usize, what: &str) -> Result<usize, String> {
    let n: usize = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a whole number of {what}"))?;
    if n > max {
        return Err(format!(
            "{n} {what} is more than {max}, the most one run takes"
        ));
    }
    Ok(n)
}

/// Parses a `--samples` value: at most [`MAX_COUNT`].
pub fn parse_samples(s: &str) -> Result<usize, String> {
    parse_up_to(s, MAX_COUNT, "samples")
}

/// Parses a `--queries` value: at most [`MAX_COUNT`].
pub fn parse_queries(s: &str) -> Result<usize, String> {
    parse_up_to(s, MAX_COUNT, "queries")
}

/// Parses a `--repeat` value: 1 to 100,000 timed runs.
pub fn parse_repeat(s: &str) -> Result<usize, String> {
    match parse_up_to(s, 100_000, "runs")? {
        0 => Err("at least 1 run is needed".into()),
        n => Ok(n),
    }
}

/// Parses a `--frames` value: at most [`MAX_FRAMES`].
pub fn parse_frames(s: &str) -> Result<usize, String> {
    parse_up_to(s, MAX_FRAMES, "frames")
}

/// A decimal number option's value.
fn parse_number(s: &str) -> Result<f64, String> {
    s.trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a number"))
}

/// Parses a `--max-negative` value: a weight the library accepts
/// ([`wavg::apps::check_max_negative`]: finite, at most 0).
pub fn parse_max_negative(s: &str) -> Result<f64, String> {
    let x = parse_number(s)?;
    wavg::apps::check_max_negative(x).map_err(|e| e.to_string())?;
    Ok(x)
}

/// Parses a `--max-stretch` value: finite and above 1 (`CorrespondOptions::check`).
pub fn parse_max_stretch(s: &str) -> Result<f64, String> {
    let x = parse_number(s)?;
    let opts = wavg::apps::CorrespondOptions {
        max_stretch: x,
        ..Default::default()
    };
    opts.check().map_err(|e| e.to_string())?;
    Ok(x)
}

/// Parses a `--max-distance` value of `wavg remesh`: finite and positive
/// ([`wavg::apps::check_max_base_distance`]).
pub fn parse_max_base_distance(s: &str) -> Result<f64, String> {
    let x = parse_number(s)?;
    wavg::apps::check_max_base_distance(x).map_err(|e| e.to_string())?;
    Ok(x)
}

/// The input files of a command for [`check_outputs`]: those always given and those
/// given when present.
pub fn inputs<'a>(
    given: impl IntoIterator<Item = &'a Path>,
    optional: impl IntoIterator<Item = &'a Option<std::path::PathBuf>>,
) -> Vec<&'a Path> {
    let mut all: Vec<&Path> = given.into_iter().collect();
    all.extend(optional.into_iter().flatten().map(|p| p.as_path()));
    all
}

/// Checks a command's outputs before any work: each (named by its option, e.g. `-o`)
/// goes to an existing folder under a name a reader would not take for another file
/// (`wavg::mesh::io::check_output_name`: no `#NAME` after `.glb`, no `.glb.gz`), standard
/// output (`-`) is not also where `--json` prints, no two outputs are one file and none is
/// one of the `inputs` (whose contents would be lost). Input errors (exit status 2).
pub fn check_outputs(
    inputs: &[&Path],
    outputs: &[(&str, &Path)],
    json: bool,
) -> Result<(), CliError> {
    for (i, &(opt, path)) in outputs.iter().enumerate() {
        if path == Path::new("-") {
            if json {
                return Err(CliError::input(format!(
                    "--json prints its report to standard output, where {opt} - writes too: \
                     give {opt} a file name"
                )));
            }
            continue;
        }
        if wavg::mesh::io::is_special_destination(path) {
            continue;
        }
        wavg::mesh::io::check_output_name(path).context(opt)?;
        if path.is_dir() {
            return Err(CliError::input(format!(
                "{opt} {}: is a folder; give a file name",
                path.display()
            )));
        }
        let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
        if let Some(dir) = parent
            && !dir.is_dir()
        {
            let why = if dir.exists() {
                format!("{} is not a folder", dir.display())
            } else {
                format!("the folder {} does not exist", dir.display())
            };
            return Err(CliError::input(format!("{opt} {}: {why}", path.display())));
        }
        for &(other, q) in &outputs[..i] {
            if same_file(q, path) {
                return Err(CliError::input(format!(
                    "{other} and {opt} name the same file {}",
                    path.display()
                )));
            }
        }
        if let Some(input) = inputs.iter().find(|&&q| same_file(q, path)) {
            return Err(CliError::input(format!(
                "{opt} {} is an input of this command ({}): write to another file",
                path.display(),
                input.display()
            )));
        }
    }
    Ok(())
}

/// Checks an output folder (named by its option) before any work: not `-` (a folder of
/// files is no one stream to write to standard output), not an existing file, and a name
/// [`check_outputs`] would take. Input errors (exit status 2).
pub fn check_output_folder(opt: &str, dir: &Path) -> Result<(), CliError> {
    if dir == Path::new("-") {
        return Err(CliError::input(format!(
            "{opt} -: this output is a folder of files, which standard output cannot take; \
             give a folder name (./- for a folder named -)"
        )));
    }
    if dir.is_file() {
        return Err(CliError::input(format!(
            "{opt} {}: is a file; {opt} names a folder",
            dir.display()
        )));
    }
    wavg::mesh::io::check_output_name(dir).context(opt)
}

/// Checks a mesh output (named by its option) before any work: a file whose extension
/// names a format the library writes (`wavg::mesh::io::check_save_path`), not `-` (the
/// format follows the extension, and standard output has none). Input errors (exit
/// status 2).
pub fn check_mesh_output(opt: &str, path: &Path) -> Result<(), CliError> {
    if path == Path::new("-") {
        return Err(CliError::input(format!(
            "{opt} -: a mesh is written to a file whose extension names its format (.obj, \
             .off, .ply, .glb, .gltf), not to standard output; give a file name"
        )));
    }
    wavg::mesh::io::check_save_path(path).context(opt)
}

/// Refuses an output `path` of a command that writes OBJ text (or glTF, by its extension)
/// when its extension names another mesh format (`.ply`, `.off`, a `.gz`): the file would
/// not hold what its name says. Other names (`-`, `.obj`, `.txt`) pass. Input error (exit
/// status 2).
pub fn refuse_other_mesh_format(path: &Path, what: &str) -> Result<(), CliError> {
    use wavg::mesh::Format;
    match Format::from_path(path) {
        Ok((Format::Obj, false) | (Format::Gltf | Format::Glb, _)) | Err(_) => Ok(()),
        Ok(_) => Err(CliError::input(format!(
            "-o {}: {what}: give a name ending in .obj, .glb or .gltf",
            path.display()
        ))),
    }
}

/// Refuses an output `path` (unless `-`) whose name does not end in `.EXT`: the command
/// writes only that kind of file (`what` says which).
pub fn require_extension(path: &Path, ext: &str, what: &str) -> Result<(), CliError> {
    let ok = path == Path::new("-")
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext));
    if ok {
        return Ok(());
    }
    Err(CliError::input(format!(
        "-o {}: {what}: give a name ending in .{ext}",
        path.display()
    )))
}

/// Whether two paths name the same file, existing or about to be written: the same
/// path after resolving links, `.` and `..` (a missing file by its folder), or on Unix
/// one file under two names (hard links).
pub fn same_file(a: &Path, b: &Path) -> bool {
    if resolved(a).is_some_and(|p| Some(p) == resolved(b)) {
        return true;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return x.is_file() && x.dev() == y.dev() && x.ino() == y.ino();
        }
    }
    false
}

/// `path` made absolute with links, `.` and `..` resolved; a file that does not exist
/// yet by its folder's resolved path and its name (`None` without such a folder).
fn resolved(path: &Path) -> Option<std::path::PathBuf> {
    if let Ok(p) = std::fs::canonicalize(path) {
        return Some(p);
    }
    let name = path.file_name()?;
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    std::fs::canonicalize(dir.unwrap_or(Path::new(".")))
        .ok()
        .map(|d| d.join(name))
}
