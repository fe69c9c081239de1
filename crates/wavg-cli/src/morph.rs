//! `wavg morph`: the source's connectivity moved onto the target through the
//! correspondence of `wavg correspond`, invalid vertices filled harmonically, and frames
//! blending linearly from the source to the mapped shape.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use wavg::apps::{MorphReport, ReasonCounts, harmonic_fill, morph_frames, morph_scene};
use wavg::mesh::io::gltf::is_gltf_path;

use crate::CliError;
use crate::correspond::{MapArgs, compute};
use crate::error::Context;
use crate::textio::{self, write_numbers};

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Maps every source vertex onto the target as `wavg correspond` does (same options), fills
the vertices that fail the validity test harmonically from the valid ones (each the average
of its neighbours, the valid ones fixed), and writes --frames OBJ files DIR/frame_000.obj ...
with the source's faces, blending linearly from the source positions (first frame) to the
mapped ones (last frame). The folder is created if needed; nothing is written on error (a
frame that cannot be written removes the frames written before it).
--json prints one object: frames, valid_fraction, seconds (map and fill, precomputation
excluded), plus the per-reason counts and the output folder.

With -o OUT.glb (or OUT.gltf, its buffer in OUT.bin) the frames go into one glTF file
instead: one mesh (the source's faces at the first frame's positions) with every frame a
morph target named frame_000, frame_001, ... (weights 0; Blender imports them as shape
keys).")]
pub struct Args {
    #[command(flatten)]
    pub map: MapArgs,
    /// Number of frames (at least 1; the first is the source, the last the mapped shape; a
    /// single frame is the mapped shape).
    #[arg(long, default_value_t = 10, value_parser = crate::common::parse_frames)]
    pub frames: usize,
    /// Output folder (or a .glb/.gltf file: the frames as morph targets of one mesh).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Print one JSON object on standard output.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` object: the [`MorphReport`] with the map's reasons, the inputs and the
/// timings (printed through `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    source: &'a str,
    target: &'a str,
    output: &'a Path,
    #[serde(flatten)]
    morph: MorphReport,
    reasons: ReasonCounts,
    seconds: f64,
    setup_seconds: f64,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.frames == 0 || args.frames > 100_000 {
        return Err(CliError::input("--frames must be between 1 and 100000"));
    }
    let gltf = is_gltf_path(&args.output);
    if gltf {
        crate::common::check_outputs(&[], &[("-o", &args.output)], args.json)?;
    } else {
        crate::common::check_output_folder("-o", &args.output)?;
    }
    let c = compute(&args.map)?;
    let t = Instant::now();
    let mesh = c.source.mesh();
    let mapped = harmonic_fill(mesh, &c.map.valid_positions()).context(&args.map.pair.source)?;
    let frames = morph_frames(&mesh.positions, &mapped, args.frames);
    let seconds = c.seconds + t.elapsed().as_secs_f64();
    if gltf {
        morph_scene(mesh, &frames)
            .save(&args.output)
            .map_err(wavg::Error::from)?;
    } else {
        write_frames(&args.output, &mesh.triangles, &frames)?;
    }
    if args.json {
        let j = serde_json::to_value(JsonReport {
            source: &args.map.pair.source,
            target: &args.map.pair.target,
            output: &args.output,
            morph: MorphReport {
                frames: args.frames,
                valid_fraction: c.map.valid_fraction(),
            },
            reasons: c.map.reason_counts(),
            seconds,
            setup_seconds: c.setup_seconds,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else {
        println!(
            "{} frames, {:.1}% of the vertices mapped directly, the rest filled -> {}",
            args.frames,
            100.0 * c.map.valid_fraction(),
            args.output.display()
        );
    }
    Ok(())
}

/// Writes the frames as OBJ files `dir/frame_000.obj`, ...: all of them or none (a frame
/// that cannot be written removes the ones before it, and the folder if this made it).
fn write_frames(
    dir: &Path,
    triangles: &[[u32; 3]],
    frames: &[Vec<wavg::Vector3<f64>>],
) -> Result<(), CliError> {
    let created = !dir.exists();
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::failure(format!("{}: {e}", dir.display())))?;
    let mut written = Vec::with_capacity(frames.len());
    for (k, f) in frames.iter().enumerate() {
        let path = dir.join(format!("frame_{k:03}.obj"));
        let r = textio::write_atomic(&path, |w: &mut dyn Write| {
            for p in f {
                write!(w, "v ")?;
                write_numbers(w, p.iter().copied())?;
                writeln!(w)?;
            }
            for t in triangles {
                let [a, b, c] = t.map(|v| v + 1);
                writeln!(w, "f {a} {b} {c}")?;
            }
            Ok(())
        });
        if let Err(e) = r {
            // Nothing half-written: the frames of this run go, and the folder if this run
            // made it.
            for p in &written {
                let _ = std::fs::remove_file(p);
            }
            if created {
                let _ = std::fs::remove_dir(dir);
            }
            return Err(e);
        }
        written.push(path);
    }
    Ok(())
}
