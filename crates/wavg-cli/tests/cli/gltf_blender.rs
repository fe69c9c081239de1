//! A `.glb` wavg writes imports into Blender (Debian's 3.4, its bundled glTF importer)
//! with its texture: an image texture node on the material and the file's vertex and face
//! counts. Blender runs hermetically (a temporary home, XDG and Blender user folders,
//! factory settings); the test is skipped when `blender` is not installed (CI has it).

use crate::common;

use std::path::Path;
use std::process::Command;

/// The script Blender runs: import, then one line `WAVG_RESULT {json}`.
const SCRIPT: &str = r#"
import bpy, json, sys
path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
# Debian's Blender 3.4 with numpy 2: the default shading guess ("NORMALS") fails on the
# removed `np.bool` for any file; "SMOOTH" takes another path.
bpy.ops.import_scene.gltf(filepath=path, import_shading="SMOOTH")
meshes = [o.data for o in bpy.context.scene.objects if o.type == "MESH"]
me = meshes[0]
images = [n.image for m in me.materials if m and m.use_nodes
          for n in m.node_tree.nodes if n.type == "TEX_IMAGE" and n.image]
print("WAVG_RESULT " + json.dumps({
    "meshes": len(meshes), "vertices": len(me.vertices), "faces": len(me.polygons),
    "uv_layers": len(me.uv_layers),
    "images": [[i.size[0], i.size[1]] for i in images],
}))
"#;

/// Blender's answer for `glb`, or `None` when Blender is not installed.
fn import_in_blender(glb: &Path) -> Option<serde_json::Value> {
    if Command::new("blender").arg("--version").output().is_err() {
        eprintln!("skipped: blender is not installed");
        return None;
    }
    let home = tempfile::tempdir().unwrap();
    let h = home.path();
    let user = h.join("blender");
    let mut cmd = Command::new("blender");
    cmd.args([
        "-b",
        "--factory-startup",
        "--python-exit-code",
        "1",
        "--python-expr",
    ])
    .arg(SCRIPT)
    .arg("--")
    .arg(glb)
    .env("HOME", h)
    .env("XDG_CONFIG_HOME", h.join(".config"))
    .env("XDG_CACHE_HOME", h.join(".cache"))
    .env("XDG_DATA_HOME", h.join(".local/share"))
    .env_remove("PYTHONPATH")
    .env_remove("PYTHONHOME");
    for (var, sub) in [
        ("BLENDER_USER_RESOURCES", ""),
        ("BLENDER_USER_CONFIG", "config"),
        ("BLENDER_USER_SCRIPTS", "scripts"),
        ("BLENDER_USER_DATAFILES", "datafiles"),
        ("BLENDER_USER_EXTENSIONS", "extensions"),
    ] {
        let d = user.join(sub);
        std::fs::create_dir_all(&d).unwrap();
        cmd.env(var, d);
    }
    let out = cmd.output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "blender: {text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("WAVG_RESULT "))
        .unwrap_or_else(|| panic!("no result from blender: {text}"));
    Some(serde_json::from_str(line).unwrap())
}

/// Vertices over the triangle primitives of the file's first mesh.
fn file_vertices(glb: &Path) -> usize {
    let g = gltf::Gltf::from_slice(&std::fs::read(glb).unwrap()).unwrap();
    let m = g.document.meshes().next().unwrap();
    m.primitives()
        .map(|p| p.get(&gltf::Semantic::Positions).unwrap().count())
        .sum()
}

#[test]
fn a_textured_glb_imports_into_blender_with_its_texture() {
    let dir = tempfile::tempdir().unwrap();
    let glb = common::decal_glb(dir.path());
    let Some(r) = import_in_blender(&glb) else {
        return;
    };
    assert_eq!(r["meshes"], 1, "{r}");
    assert_eq!(r["faces"], 5120, "{r}");
    assert_eq!(r["vertices"], file_vertices(&glb), "{r}");
    assert_eq!(r["uv_layers"], 1, "{r}");
    let images = r["images"].as_array().unwrap();
    assert_eq!(images.len(), 1, "one image texture node: {r}");
    assert!(images[0][0].as_u64().unwrap() > 0, "{r}");
}
