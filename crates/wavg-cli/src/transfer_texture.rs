//! `wavg transfer-texture`: carries a texture from one textured mesh to another through
//! corresponding anchors (inverse problem on the target, forward problem on the source).

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use wavg::apps::{
    Image, TextureTransfer, TransferOptions, check_uv, textured_scene, transfer_texture,
};
use wavg::mesh::io::gltf::is_gltf_path;

use crate::CliError;
use crate::apps_common::{PairArgs, solver_for};
use crate::common::load_mesh;
use crate::error::Context;
use crate::render::{parse_size, write_png};
use crate::textio::read_points;

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
For every texel of the target's texture atlas covered by a triangle (in the target's UV
layout): its point on the target, its weights with respect to the target anchors (the
verified inverse by default: weights that lead back to the point), their weighted average
over the source anchors (the forward problem: the corresponding point on the source), and
the source texture sampled bilinearly at that point's UV. Anchor i of --source-anchors
corresponds to anchor i of --target-anchors (anchors format: `v VERTEX` or
`f FACE B0 B1 B2`). Uncovered texels and texels without a source point are transparent
(RGBA output); 4 rings of texels around the charts are filled (seam dilation). With -o
OUT.glb (or OUT.gltf, its buffer in OUT.bin) the target mesh is written with the new
texture embedded as its base colour texture (PNG) instead.

Without --source-embedding / --target-embedding the embeddings are precomputed in memory
(a progress bar shows on a terminal). --size W[xH] sets the output (default: the source
texture's size). The source texture is --source-texture (PNG or JPEG), or else the base
colour texture of a glTF source mesh (embedded, or a file beside the .gltf). Bad input
(anchor counts that differ, a mesh without UVs, an unreadable texture or none, anchors out
of range) is an error and nothing is written.

--json prints one object: texels (covered texels, each an inverse and a forward problem),
valid_fraction (of them with a source point), seconds (the transfer, precomputation
excluded), texels_per_s, plus width, height, atlas_texels, valid_texels, not_reached
(verified weights that missed the point; the paper's weights were used), dilated_texels,
precompute_s, verified, stride, interpolated_texels.

--stride N (default 4): texels on every N-th row and column of the atlas are solved exactly;
a texel between four of them whose source UVs lie close together (one chart, no seam in
between) takes their bilinear interpolation; every other covered texel is solved exactly.
--stride 1 solves every texel.

Spot onto itself (same anchors) reproduces its texture with a mean colour error of 0.06 (of
255) over the covered texels, and onto a stretched, bent copy 3.6 (cargo test -p wavg-apps
--test apps transfer).")]
pub struct Args {
    #[command(flatten)]
    pub pair: PairArgs,
    /// Source texture (PNG or JPEG; default: the base colour texture of a glTF source).
    #[arg(long)]
    pub source_texture: Option<PathBuf>,
    /// Output size W or WxH (default: the source texture's).
    #[arg(long)]
    pub size: Option<String>,
    /// Output PNG (RGBA), or .glb/.gltf: the target mesh with the new texture embedded as
    /// its base colour (PNG).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Use the paper's inverse only (faster; weights need not lead back to the point).
    #[arg(long)]
    pub paper: bool,
    /// Solve texels on every N-th row and column exactly and interpolate between them
    /// inside a chart (1: solve every texel; at most 64).
    #[arg(long, default_value_t = wavg::apps::TransferOptions::default().stride, value_parser = clap::value_parser!(u32).range(1..=wavg::apps::MAX_STRIDE as i64))]
    pub stride: u32,
    /// Print one JSON object on standard output.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` object: the library's [`TextureTransfer`] counts with the atlas, the
/// settings and the timings (printed through `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    #[serde(flatten)]
    transfer: &'a TextureTransfer,
    valid_fraction: f64,
    seconds: f64,
    texels_per_s: f64,
    width: u32,
    height: u32,
    atlas_texels: u64,
    precompute_s: f64,
    verified: bool,
    stride: u32,
}

/// The base colour texture of the source mesh's file, or an error asking for
/// --source-texture.
fn source_texture(mesh: &str) -> Result<Image, CliError> {
    let (_, notes) = crate::common::load_mesh_notes(mesh)?;
    wavg::mesh_texture(&notes)?.ok_or_else(|| {
        CliError::input(format!(
            "{mesh} carries no base colour texture: give --source-texture (PNG or JPEG)"
        ))
    })
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let inputs = crate::common::inputs([], [&args.source_texture]);
    crate::common::check_outputs(&inputs, &[("-o", &args.output)], args.json)?;
    if !is_gltf_path(&args.output) {
        crate::common::require_extension(
            &args.output,
            "png",
            "the texture is written as a PNG file (or .glb/.gltf: the target with it)",
        )?;
    }
    crate::textio::with_threads(args.pair.threads, || run_inner(args))?
}

fn run_inner(args: Args) -> Result<(), CliError> {
    // Cheap checks first: anchors, UVs, texture.
    let (sa, ta) = (
        read_points(&args.pair.source_anchors)?,
        read_points(&args.pair.target_anchors)?,
    );
    if sa.len() != ta.len() {
        return Err(CliError::input(format!(
            "{} has {} anchors and {} has {}: they must correspond one to one",
            args.pair.source_anchors.display(),
            sa.len(),
            args.pair.target_anchors.display(),
            ta.len()
        )));
    }
    for (mesh, what) in [(&args.pair.source, "source"), (&args.pair.target, "target")] {
        let m = load_mesh(mesh)?;
        check_uv(&m, what).context(mesh)?;
    }
    let texture = match &args.source_texture {
        Some(path) => Image::read(path)?,
        None => source_texture(&args.pair.source)?,
    };
    if args.stride == 0 {
        return Err(CliError::input("--stride must be at least 1"));
    }
    let (width, height) = match &args.size {
        Some(s) => parse_size(s, "--size")?,
        None => (texture.width, texture.height),
    };
    let visible = std::io::stderr().is_terminal() && !args.json;
    let t0 = Instant::now();
    let source = solver_for(
        &args.pair.source,
        args.pair.source_embedding.as_deref(),
        &args.pair.source_anchors,
        args.pair.cache,
    )?;
    let target = solver_for(
        &args.pair.target,
        args.pair.target_embedding.as_deref(),
        &args.pair.target_anchors,
        args.pair.cache,
    )?;
    let precompute_s = t0.elapsed().as_secs_f64();
    let opts = TransferOptions {
        width,
        height,
        verified: !args.paper,
        stride: args.stride,
        ..Default::default()
    };
    let bar = ProgressBar::with_draw_target(
        Some(0),
        if visible {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        },
    );
    bar.set_style(
        ProgressStyle::with_template("  transfer [{bar:40}] {percent:>3}% {elapsed:>4}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let t = Instant::now();
    let out = transfer_texture(&source, &texture, &target, &opts, &|done, all| {
        bar.set_length(all as u64);
        bar.set_position(done as u64);
    })?;
    let seconds = t.elapsed().as_secs_f64();
    bar.finish_and_clear();
    if is_gltf_path(&args.output) {
        let scene = textured_scene(target.mesh().mesh(), &out.image).map_err(wavg::Error::from)?;
        scene.save(&args.output).map_err(wavg::Error::from)?;
    } else {
        write_png(&args.output, &out.image)?;
    }
    let valid_fraction = if out.covered > 0 {
        out.valid as f64 / out.covered as f64
    } else {
        0.0
    };
    let rate = out.covered as f64 / seconds.max(1e-12);
    if args.json {
        let j = serde_json::to_value(JsonReport {
            transfer: &out,
            valid_fraction,
            seconds,
            texels_per_s: rate,
            width,
            height,
            atlas_texels: width as u64 * height as u64,
            precompute_s,
            verified: !args.paper,
            stride: args.stride,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else {
        println!(
            "{} texels covered, {:.4} with a source point, {seconds:.2} s ({:.2} M texels/s) \
             -> {}",
            out.covered,
            valid_fraction,
            rate / 1e6,
            args.output.display()
        );
    }
    Ok(())
}
