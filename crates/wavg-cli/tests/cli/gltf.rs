//! glTF meshes through the command line: `wavg info` reports the welded surface (its
//! vertex count, the copies merged, the genus), `FILE#NAME` picks a mesh, `render` draws
//! the embedded base colour texture and `transfer-texture` takes it as the source texture.

use crate::common;

use common::{json_object, s, wavg, wavg_ok};
use wavg::apps::Image;
use wavg_testdata::gltf::{textured_torus_glb, torus_glb};

fn png(fill: [u8; 4]) -> Vec<u8> {
    let mut out = Vec::new();
    Image::new(4, 4, fill)
        .unwrap()
        .encode_png(&mut out)
        .unwrap();
    out
}

/// Pixels of a PNG file that are clearly red.
fn red_pixels(path: &std::path::Path) -> usize {
    let img = Image::read_png(path).unwrap();
    img.pixels
        .iter()
        .filter(|p| p[0] > 150 && p[1] < 90 && p[2] < 90)
        .count()
}

#[test]
fn info_reports_the_welded_closed_surface() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("torus.glb");
    std::fs::write(&glb, torus_glb(12, 8, "Torus").1).unwrap();
    let (o, _) = json_object(&wavg_ok(&["info", &s(&glb), "--json"]));
    assert_eq!(o["vertices"], 96);
    assert_eq!(o["welded_vertices"], 13 * 9 - 96);
    assert_eq!(o["genus"], 1);
    assert_eq!(
        (o["valid"].as_bool(), o["uv"].as_bool()),
        (Some(true), Some(true))
    );
    let text = String::from_utf8(wavg_ok(&["info", &s(&glb)]).stdout).unwrap();
    assert!(
        text.contains("welded:               21 vertex copies"),
        "{text}"
    );
    // One mesh by name; an unknown name is bad input (status 2) naming the meshes.
    let named = format!("{}#Torus", s(&glb));
    let (o, _) = json_object(&wavg_ok(&["info", &named, "--json"]));
    assert_eq!(
        (o["faces"].as_u64(), o["mesh"].as_str()),
        (Some(192), Some(&*named))
    );
    let out = wavg(&["info", &format!("{}#Body", s(&glb))]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("torus.glb") && err.contains("\"Torus\""),
        "{err}"
    );
    let out = wavg(&["info", &s(&dir.path().join("missing.glb"))]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn render_draws_the_embedded_base_colour_texture() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("torus.glb");
    std::fs::write(&glb, textured_torus_glb(24, 12, &png([220, 20, 20, 255]))).unwrap();
    let out = dir.path().join("r.png");
    wavg_ok(&["render", &s(&glb), "-o", &s(&out), "--size", "64x48"]);
    assert!(red_pixels(&out) > 200, "{}", red_pixels(&out));
    // --texture overrides it.
    let green = dir.path().join("green.png");
    std::fs::write(&green, png([20, 220, 20, 255])).unwrap();
    wavg_ok(&[
        "render",
        &s(&glb),
        "--texture",
        &s(&green),
        "-o",
        &s(&out),
        "--size",
        "64x48",
    ]);
    assert_eq!(red_pixels(&out), 0);
}

#[test]
fn transfer_texture_takes_a_gltf_sources_texture() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("torus.glb");
    std::fs::write(&glb, textured_torus_glb(24, 12, &png([220, 20, 20, 255]))).unwrap();
    let anchors = dir.path().join("a.txt");
    std::fs::write(&anchors, "v 0\nv 75\nv 150\nv 225\nv 5\n").unwrap();
    let out = dir.path().join("t.png");
    let run = |source: &str| {
        wavg(&[
            "transfer-texture",
            "--source",
            source,
            "--target",
            &s(&glb),
            "--source-anchors",
            &s(&anchors),
            "--target-anchors",
            &s(&anchors),
            "-o",
            &s(&out),
            "--size",
            "16",
            "--no-cache",
        ])
    };
    let r = run(&s(&glb));
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(red_pixels(&out) > 64, "{}", red_pixels(&out));
    // A source without a texture of its own needs --source-texture.
    std::fs::remove_file(&out).unwrap();
    let obj = dir.path().join("torus.obj");
    wavg_ok(&["repair", &s(&glb), "-o", &s(&obj)]);
    let r = run(&s(&obj));
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains("--source-texture"), "{err}");
    assert!(!out.exists());
}
