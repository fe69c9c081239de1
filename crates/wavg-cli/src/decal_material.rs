//! The material files of `wavg decal`: a `.mtl` beside the OBJ naming the decal's image
//! (the given texture, or a generated checkerboard PNG written beside it), so that the
//! OBJ opens textured in a viewer and in `wavg render`.

use std::io::Write;
use std::path::{Path, PathBuf};

use wavg::apps::{DECAL_MATERIAL as TEXTURED, Image, PLAIN_MATERIAL as PLAIN};

use crate::CliError;
use crate::error::Context;
use crate::textio;

/// What was written beside the OBJ.
pub struct Material {
    /// The `.mtl` file.
    pub mtl: PathBuf,
    /// The image it names (the given texture or the generated checkerboard).
    pub texture: PathBuf,
    /// Whether the image is the checkerboard this command wrote.
    pub generated: bool,
}

impl Material {
    /// Removes the files written for this material (the OBJ naming them could not be
    /// written: nothing of the command is left).
    pub fn remove(&self) {
        let _ = std::fs::remove_file(&self.mtl);
        if self.generated {
            let _ = std::fs::remove_file(&self.texture);
        }
    }

    /// The `mtllib` line's argument: the `.mtl`'s file name (it sits beside the OBJ).
    pub fn file_name(&self) -> String {
        self.mtl
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
    }
}

/// The `.mtl` and the checkerboard image written beside the OBJ `obj`: `STEM.mtl` and
/// `STEM_checker.png`.
pub fn side_files(obj: &Path) -> (PathBuf, PathBuf) {
    let dir = obj.parent().unwrap_or(Path::new(""));
    let stem = obj
        .file_stem()
        .map_or_else(|| "decal".into(), |s| s.to_string_lossy().into_owned());
    (
        dir.join(format!("{stem}.mtl")),
        dir.join(format!("{stem}_checker.png")),
    )
}

/// Writes `STEM.mtl` beside `obj` naming `texture` (checked by [`check_texture`]), or a
/// checkerboard `STEM_checker.png` written beside it when there is none. Nothing is
/// written for standard output (`-`).
pub fn write(obj: &Path, texture: Option<&Path>) -> Result<Option<Material>, CliError> {
    if obj == Path::new("-") {
        return Ok(None);
    }
    let dir = obj.parent().unwrap_or(Path::new(""));
    let (mtl, checker) = side_files(obj);
    let texture_arg = texture;
    let texture = match texture {
        Some(t) => t.to_path_buf(),
        None => {
            let t = checker;
            let board = crate::demo_pictures::decal_board().map_err(CliError::failure)?;
            crate::render::write_png(&t, &board)?;
            t
        }
    };
    let generated = texture_arg.is_none();
    let name = relative_to(&texture, dir);
    let material = Material {
        mtl,
        texture,
        generated,
    };
    textio::write_atomic(&material.mtl, |w: &mut dyn Write| {
        writeln!(w, "# written by wavg decal")?;
        writeln!(w, "newmtl {TEXTURED}")?;
        writeln!(w, "Ka 1 1 1\nKd 1 1 1\nKs 0 0 0\nd 1\nillum 1")?;
        writeln!(w, "map_Kd {name}")?;
        writeln!(w, "\nnewmtl {PLAIN}")?;
        writeln!(w, "Ka 1 1 1\nKd 0.8 0.82 0.85\nKs 0 0 0\nd 1\nillum 1")
    })
    .inspect_err(|_| material.remove())?;
    Ok(Some(material))
}

/// The PNG a glTF decal embeds: the file `texture`, or the checkerboard encoded.
pub fn png_bytes(texture: Option<&Path>) -> Result<Vec<u8>, CliError> {
    match texture {
        Some(t) => {
            std::fs::read(t).map_err(|e| CliError::input(format!("--texture {}: {e}", t.display())))
        }
        None => {
            let board = crate::demo_pictures::decal_board().map_err(CliError::failure)?;
            let mut png = Vec::new();
            board.encode_png(&mut png).map_err(wavg::Error::from)?;
            Ok(png)
        }
    }
}

/// Refuses a `--texture` that is not a readable PNG (before anything is computed).
pub fn check_texture(texture: &Path) -> Result<(), CliError> {
    Image::read_png(texture).map(drop).context("--texture")
}

/// How a `.mtl` in `dir` names `file`: its file name when it is in `dir`, else its
/// absolute path (material paths are relative to the `.mtl`).
fn relative_to(file: &Path, dir: &Path) -> String {
    let canon = |p: &Path| {
        std::fs::canonicalize(if p == Path::new("") {
            Path::new(".")
        } else {
            p
        })
    };
    let parent = file.parent().unwrap_or(Path::new(""));
    match (canon(parent), canon(dir)) {
        (Ok(a), Ok(b)) if a == b => file
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
        _ => canon(file)
            .unwrap_or_else(|_| file.to_path_buf())
            .display()
            .to_string(),
    }
}
