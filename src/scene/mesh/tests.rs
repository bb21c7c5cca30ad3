use super::*;

/// A unit square as two triangles' worth of PLY, in `format`, with the
/// face written as one quad (fanned on reading).
fn square_ply(format: &str, big: bool) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment a square\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes();
    let verts = [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    if format == "ascii" {
        for v in verts {
            out.extend(format!("{} {} {} 0 0 1 {} {}\n", v[0], v[1], v[2], v[0], v[1]).bytes());
        }
        out.extend(b"4 0 1 2 3\n");
        return out;
    }
    let f = |x: f32| {
        if big {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    for v in verts {
        for x in [v[0], v[1], v[2], 0.0, 0.0, 1.0, v[0], v[1]] {
            out.extend(f(x));
        }
    }
    out.push(4);
    for i in 0..4i32 {
        out.extend(if big {
            i.to_be_bytes()
        } else {
            i.to_le_bytes()
        });
    }
    out
}

#[test]
fn a_ply_square_reads_alike_in_ascii_and_both_byte_orders() {
    for (format, big) in [
        ("ascii", false),
        ("binary_little_endian", false),
        ("binary_big_endian", true),
    ] {
        let m = ply::parse(&square_ply(format, big)).unwrap_or_else(|e| panic!("{format}: {e}"));
        m.check().unwrap();
        assert_eq!(m.triangles, [[0, 1, 2], [0, 2, 3]], "{format}");
        assert_eq!(m.positions[2], [1.0, 1.0, 0.0], "{format}");
        assert_eq!(m.normals, [[0.0, 0.0, 1.0]; 4], "{format}");
        assert_eq!(m.texcoords[3], [0.0, 1.0], "{format}");
    }
}

#[test]
fn an_obj_reads_with_its_normals_and_texture_coordinates() {
    let obj = "# a square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n";
    let m = obj::parse(obj.as_bytes()).unwrap();
    m.check().unwrap();
    assert_eq!(m.triangles.len(), 2);
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.normals, [[0.0, 0.0, 1.0]; 4]);
    assert_eq!(m.texcoords.len(), 4);
    let bare = obj::parse(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert!(bare.normals.is_empty() && bare.texcoords.is_empty());
}

/// What a hostile or broken file gets: an error saying what is wrong.
fn refusal(bytes: &[u8], ext: &str) -> String {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join(format!("m.{ext}"));
    std::fs::write(&p, bytes).unwrap();
    let e = read(&p).unwrap_err().to_string();
    assert!(e.starts_with(&p.display().to_string()), "{e}");
    assert!(!e.contains('\n'), "{e}");
    e
}

#[test]
fn broken_files_are_refused_in_one_line_naming_the_file() {
    let good = square_ply("binary_little_endian", false);
    let e = refusal(&good[..good.len() - 3], "ply");
    assert!(e.contains("truncated"), "{e}");
    let ascii = String::from_utf8(square_ply("ascii", false)).unwrap();
    let e = refusal(ascii.replace("4 0 1 2 3", "3 0 1 9").as_bytes(), "ply");
    assert!(e.contains("face 0 uses vertex 9 of 4"), "{e}");
    let e = refusal(
        ascii.replace("1 1 0 0 0 1", "nan 1 0 0 0 1").as_bytes(),
        "ply",
    );
    assert!(e.contains("vertex 2 is not finite"), "{e}");
    let e = refusal(ascii.replace("4 0 1 2 3", "2 0 1").as_bytes(), "ply");
    assert!(e.contains("face 0 has 2 vertices"), "{e}");
    let e = refusal(
        ascii.replace("element face 1", "element face 0").as_bytes(),
        "ply",
    );
    assert!(e.contains("no faces"), "{e}");
    let e = refusal(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", "obj");
    assert!(e.contains("not a readable mesh"), "{e}");
    let e = refusal(b"just text", "stl");
    assert!(e.contains("expected a .ply or .obj"), "{e}");
}

/// 2^31 faces declared in a file of a few hundred bytes: refused by the
/// count against the size, before anything is allocated.
#[test]
fn a_huge_declared_count_is_refused_before_allocating() {
    // the header edited, the body kept byte for byte
    let edit = |bytes: &[u8], from: &str, to: &str| {
        let end = bytes
            .windows(11)
            .position(|w| w == b"end_header\n")
            .unwrap()
            + 11;
        let mut out = String::from_utf8(bytes[..end].to_vec())
            .unwrap()
            .replace(from, to)
            .into_bytes();
        out.extend(&bytes[end..]);
        out
    };
    for format in ["ascii", "binary_little_endian"] {
        let ply = square_ply(format, false);
        let e = refusal(
            &edit(&ply, "element face 1", "element face 2147483648"),
            "ply",
        );
        assert!(
            e.contains("declares 2147483648 face elements"),
            "{format}: {e}"
        );
        let huge = edit(
            &ply,
            "element vertex 4",
            "element vertex 18446744073709551615",
        );
        let e = refusal(&huge, "ply");
        assert!(e.contains("more than its"), "{format}: {e}");
    }
}
