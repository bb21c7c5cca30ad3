//! The structure the architecture promises (docs/architecture.md): no
//! function over 80 lines, no import circle between files nor between the
//! members of any folder, no effect name (from the registry) written as a
//! string outside diagnose/effects/, no run directory file name (from
//! rundir's constants) written in a string outside rundir/. Checked by
//! scripts/structure.py, which lists what it finds.

#[test]
fn the_source_tree_keeps_its_structure() {
    let root = env!("CARGO_MANIFEST_DIR");
    let out = std::process::Command::new("python3")
        .arg(format!("{root}/scripts/structure.py"))
        .output()
        .expect("python3 runs scripts/structure.py");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("functions over 80 lines: 0"), "{text}");
}

/// Writes `files` (path, text) under a fresh directory's src/.
fn tree(files: &[(&str, &str)]) -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    for (path, text) in files {
        let p = d.path().join("src").join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }
    d
}

fn check(root: &std::path::Path) -> (bool, String) {
    let script = format!("{}/scripts/structure.py", env!("CARGO_MANIFEST_DIR"));
    let out = std::process::Command::new("python3")
        .arg(script)
        .arg("--root")
        .arg(root)
        .output()
        .expect("python3 runs scripts/structure.py");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).to_string(),
    )
}

/// The registry and rundir every checked tree has: one effect, one file.
const REGISTRY: (&str, &str) = (
    "diagnose/effects/mod.rs",
    "mod glow;\npub static ALL: &[&dyn Effect] = &[&glow::Glow];\n",
);
const GLOW: (&str, &str) = (
    "diagnose/effects/glow.rs",
    "pub struct Glow;\nimpl Effect for Glow {\n    fn name(&self) -> &'static str {\n        \"glow\"\n    }\n}\n",
);
const RUNDIR: (&str, &str) = (
    "rundir/mod.rs",
    "pub const NOTES: &str = \"notes.txt\";\npub fn shot_name(s: &str) -> String {\n    format!(\"shot_{s}.png\")\n}\n",
);

#[test]
fn a_circle_through_a_parent_and_names_spelled_outside_their_owner_fail() {
    let d = tree(&[
        REGISTRY,
        GLOW,
        RUNDIR,
        ("lib.rs", "pub mod diagnose;\npub mod rundir;\npub mod a;\n"),
        // a/mod.rs calls its child, and the child uses a type a/mod.rs
        // defines: a circle between files, though `use super::` hides it.
        (
            "a/mod.rs",
            "mod child;\npub struct Kind;\npub fn run() {\n    child::go();\n}\n",
        ),
        (
            "a/child.rs",
            "use super::Kind;\npub fn go() {\n    let _ = \"glow\";\n    let _ = format!(\"see {}/notes.txt\", 1);\n    let _ = \"shot_{k}.png\";\n}\nconst OUT: &str = \"out.json\";\n",
        ),
    ]);
    let (ok, text) = check(d.path());
    assert!(!ok, "{text}");
    assert!(text.contains("import circles between files: 1"), "{text}");
    assert!(text.contains("a -> a::child"), "{text}");
    assert!(text.contains("a::child -> a "), "{text}");
    assert!(text.contains("src/a/child.rs:3 \"glow\""), "{text}");
    assert!(
        text.contains("src/a/child.rs:4 \"see {}/notes.txt\""),
        "{text}"
    );
    assert!(text.contains("src/a/child.rs:5 \"shot_{k}.png\""), "{text}");
    assert!(
        text.contains("src/a/child.rs:7 OUT = \"out.json\""),
        "{text}"
    );
}

#[test]
fn a_type_moved_to_a_leaf_and_a_re_export_make_no_circle() {
    let d = tree(&[
        REGISTRY,
        GLOW,
        RUNDIR,
        ("lib.rs", "pub mod diagnose;\npub mod rundir;\npub mod a;\n"),
        // The type in a leaf, re-exported by a/mod.rs: the child's
        // `super::Kind` is an edge to the leaf, not to a/mod.rs.
        (
            "a/mod.rs",
            "mod child;\nmod kind;\npub use kind::Kind;\npub fn run() {\n    child::go();\n}\n",
        ),
        ("a/kind.rs", "pub struct Kind;\n"),
        (
            "a/child.rs",
            "use super::Kind;\nuse crate::rundir::NOTES;\npub fn go() {}\n",
        ),
    ]);
    let (ok, text) = check(d.path());
    assert!(ok, "{text}");
    assert!(text.contains("import circles between files: 0"), "{text}");
}
