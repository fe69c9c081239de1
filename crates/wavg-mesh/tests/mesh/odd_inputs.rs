//! Odd but legal text files read, and odd values refused in words a user reads: a Latin-1
//! byte in an OBJ comment, OBJ statements continued with `\`, a negative PLY list length.

use std::path::Path;

use wavg_mesh::Format;
use wavg_mesh::io::parse_bytes;

#[test]
fn obj_comments_are_skipped_whatever_their_bytes() {
    let mut file = b"# made by Ren\xe9 (Latin-1)\nv 0 0 0\nv 1 0 0 # caf\xe9\nv 0 1 0\n".to_vec();
    file.extend_from_slice(b"f 1 2 3\n");
    let (m, _) = parse_bytes(&file, Format::Obj, Path::new("latin1.obj")).unwrap();
    assert_eq!((m.positions.len(), m.triangles.len()), (3, 1));
    // Outside a comment such a byte is still refused, with its line.
    let e = parse_bytes(b"v 0 0 0\nv 1 0 \xe9\n", Format::Obj, Path::new("b.obj")).unwrap_err();
    assert!(e.to_string().contains("b.obj:2"), "{e}");
}

#[test]
fn obj_statements_continue_over_a_backslash() {
    let file = b"v 0 0 \\\n 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 \\\n2 \\\n 3\nf 1 2 4\nbad\\\n";
    let (m, _) = parse_bytes(file, Format::Obj, Path::new("cont.obj")).unwrap();
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 1, 3]]);
    // An error in a continued statement names its first line.
    let e = parse_bytes(b"v 0 0 0\nv 1 \\\n x 0\n", Format::Obj, Path::new("c.obj")).unwrap_err();
    assert!(e.to_string().contains("c.obj:2"), "{e}");
}

#[test]
fn ply_values_are_named_as_a_user_writes_them() {
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                end_header\n0 0 0\n1 0 0\n0 1 0\n";
    let negative = head.replace("list uchar int", "list int int") + "-5 0 1 2\n";
    let e = parse_bytes(negative.as_bytes(), Format::Ply, Path::new("n.ply")).unwrap_err();
    let m = e.to_string();
    assert!(m.contains("list length -5 in element 'face'"), "{m}");
    assert!(!m.contains("Int("), "{m}");
    let e = parse_bytes(
        (head.to_string() + "3 0 1 x\n").as_bytes(),
        Format::Ply,
        Path::new("t.ply"),
    )
    .unwrap_err();
    let m = e.to_string();
    assert!(m.contains("\"x\" is not a value of type int"), "{m}");
}
