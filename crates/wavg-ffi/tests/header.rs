//! `include/wavg.h` is exactly what cbindgen generates from this crate (set
//! `WAVG_UPDATE_HEADER=1` to rewrite it), and its version block matches the package.

use std::path::{Path, PathBuf};

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn header_path() -> PathBuf {
    crate_dir().join("../../include/wavg.h")
}

fn generate() -> String {
    let dir = crate_dir();
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut out = Vec::new();
    cbindgen::Builder::new()
        .with_crate(&dir)
        .with_config(config)
        .generate()
        .expect("cbindgen failed on the crate")
        .write(&mut out);
    String::from_utf8(out).expect("UTF-8 header")
}

#[test]
fn header_is_up_to_date() {
    let fresh = generate();
    let path = header_path();
    if std::env::var_os("WAVG_UPDATE_HEADER").is_some() {
        std::fs::write(&path, &fresh).expect("write include/wavg.h");
        return;
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        checked_in == fresh,
        "{} is not what cbindgen generates from crates/wavg-ffi; regenerate it with \
         `WAVG_UPDATE_HEADER=1 cargo test -p wavg-ffi --test header`",
        Path::new("include/wavg.h").display()
    );
}

#[test]
fn version_block_matches_the_package() {
    let header = generate();
    for (name, value) in [
        ("WAVG_VERSION_MAJOR", env!("CARGO_PKG_VERSION_MAJOR")),
        ("WAVG_VERSION_MINOR", env!("CARGO_PKG_VERSION_MINOR")),
        ("WAVG_VERSION_PATCH", env!("CARGO_PKG_VERSION_PATCH")),
    ] {
        let line = format!("#define {name} {value}");
        assert!(header.contains(&line), "missing `{line}`");
    }
    assert!(header.contains("#define WAVG_ABI_VERSION 0"));
}
