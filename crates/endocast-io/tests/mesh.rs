//! Mesh files: every format written and read back, and bad files refused with an error that
//! names the file, without allocating for counts the file cannot hold.

use endocast_core::scene::TriangleMesh;
use endocast_io::mesh::{read_mesh, write_mesh};
use endocast_io::ReadError;
use glam::DVec3;
use std::path::Path;

fn tetrahedron() -> TriangleMesh {
    let v = vec![
        DVec3::new(1.5, -2.0, 3.0),
        DVec3::new(11.5, -2.0, 3.0),
        DVec3::new(1.5, 8.0, 3.0),
        DVec3::new(1.5, -2.0, 13.0),
    ];
    TriangleMesh::new(v, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]).unwrap()
}

#[test]
fn every_format_reads_back_what_was_written() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = tetrahedron();
    for name in ["t.stl", "t.obj", "t.ply"] {
        let path = dir.path().join(name);
        write_mesh(&path, &mesh).unwrap();
        let back = read_mesh(&path).unwrap();
        assert_eq!(back.triangles().len(), 4, "{name}");
        for i in 0..4 {
            assert_eq!(back.corners(i), mesh.corners(i), "{name}");
        }
    }
    // ASCII STL and ASCII PLY with quads and extra properties.
    let stl = "solid x\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  \
               vertex 0 1 0\n endloop\nendfacet\nendsolid x\n";
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
               property float z\nproperty uchar red\nelement face 1\n\
               property list uchar int vertex_indices\nend_header\n0 0 0 9\n1 0 0 9\n1 1 0 9\n\
               0 1 0 9\n4 0 1 2 3\n";
    for (name, text, triangles) in [("a.stl", stl, 1), ("a.ply", ply, 2)] {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        assert_eq!(
            read_mesh(&path).unwrap().triangles().len(),
            triangles,
            "{name}"
        );
    }
}

/// The error reading `bytes` as file `name`, which must name the file and contain `words`.
fn refused(dir: &Path, name: &str, bytes: &[u8], words: &str) -> ReadError {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let error = read_mesh(&path).unwrap_err();
    let message = error.to_string();
    assert!(message.contains(name), "{message}");
    assert!(message.contains(words), "{name}: {message}");
    error
}

#[test]
fn bad_files_are_refused_with_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    refused(
        d,
        "index.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
        "vertex 8",
    );
    refused(
        d,
        "nan.obj",
        b"v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n",
        "not finite",
    );
    refused(
        d,
        "two.obj",
        b"v 0 0 0\nv 1 0 0\nf 1 2\n",
        "face with 2 vertices",
    );
    refused(
        d,
        "zero.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
        "not a vertex",
    );
    let two = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
               property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
               end_header\n0 0 0\n1 0 0\n2 0 1\n";
    refused(d, "two.ply", two.as_bytes(), "face with 2 vertices");
    let stl2 = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n";
    refused(d, "two.stl", stl2.as_bytes(), "2 vertices");
    // A binary STL cut short: the header promises two triangles.
    let mut binary = vec![0u8; 80];
    binary.extend(2u32.to_le_bytes());
    binary.extend([0u8; 70]);
    refused(d, "cut.stl", &binary, "truncated");
    // A header claiming about two billion triangles (100 GB) in a tiny file.
    let mut huge = vec![0u8; 80];
    huge.extend(2_000_000_000u32.to_le_bytes());
    huge.extend([0u8; 50]);
    refused(d, "huge.stl", &huge, "2000000000 triangles");
    let ply = "ply\nformat binary_little_endian 1.0\nelement vertex 2000000000\n\
               property float x\nproperty float y\nproperty float z\nend_header\n\0\0\0\0";
    refused(d, "huge.ply", ply.as_bytes(), "too short");
    let ply = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
               property float y\nproperty float z\nend_header\n\0\0\0\0";
    refused(d, "cut.ply", ply.as_bytes(), "too short");
    refused(d, "nothing.obj", b"# empty\n", "no triangle");
    let path = d.join("mesh.vtk");
    std::fs::write(&path, b"x").unwrap();
    assert!(read_mesh(&path)
        .unwrap_err()
        .to_string()
        .contains("mesh.vtk"));
}
