//! What `include:` may read: files under the main tree file's folder, unless
//! `--allow-include-outside`; and a file that is not a tree shows at most one line in the
//! diagnostics (issue 13, item 13).

use std::path::{Path, PathBuf};

use crate::support::cli;
use cli::*;

fn tree_including(dir: &Path, include: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let tree = dir.join("t.yaml");
    std::fs::write(&tree, format!("include: [{include}]\nmain: {{home: {{}}}}\n")).unwrap();
    tree
}

const SECRET: &str = "api_token: s3cr3t-value-1\npassword: s3cr3t-value-2\nkey: s3cr3t-value-3\n";

#[test]
fn include_cannot_read_outside_the_tree_folder() {
    let dir = scratch("outside");
    let root = dir.join("project");
    std::fs::create_dir_all(root.join("lib")).unwrap();
    std::fs::write(dir.join("secret.yaml"), SECRET).unwrap();
    std::os::unix::fs::symlink(dir.join("secret.yaml"), root.join("lib/link.yaml")).unwrap();
    std::os::unix::fs::symlink(&dir, root.join("up")).unwrap();
    for include in [
        "/etc/passwd",
        "/proc/self/environ",
        "../secret.yaml",
        "lib/../../secret.yaml",
        "lib/link.yaml",
        "up/secret.yaml",
        s(&dir.join("secret.yaml")),
    ] {
        let tree = tree_including(&root, include);
        let out = macrotree(&["validate", s(&tree)]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{include}: {stderr}");
        assert!(
            stderr.contains("is outside the tree's folder"),
            "{include}: {stderr}"
        );
        assert!(stderr.contains("--allow-include-outside"), "{include}: {stderr}");
        for leak in ["s3cr3t", "root:x:", "PATH="] {
            assert!(!stderr.contains(leak), "{include}: leaked {leak:?}: {stderr}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn includes_under_the_tree_folder_still_load() {
    for tree in [
        "trees/library_pick_place.yaml",
        "tests/fixtures/trees/pick_place.yaml",
        "tests/fixtures/trees/include_cycle.yaml",
    ] {
        let out = macrotree(&["validate", tree]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{tree}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    // A library in a subfolder may include a sibling through `..`, staying in the tree folder.
    let dir = scratch("inside");
    std::fs::create_dir_all(dir.join("lib/more")).unwrap();
    std::fs::write(
        dir.join("lib/more/a.yaml"),
        "include: [../b.yaml]\nsubtrees:\n  a: {root: {subtree: {ref: b}}}\n",
    )
    .unwrap();
    std::fs::write(dir.join("lib/b.yaml"), "subtrees:\n  b: {root: {home: {}}}\n").unwrap();
    let tree = dir.join("t.yaml");
    std::fs::write(&tree, "include: [lib/more/a.yaml]\nmain: {subtree: {ref: a}}\n").unwrap();
    let out = macrotree(&["validate", s(&tree)]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn allow_include_outside_reads_a_library_elsewhere() {
    let dir = scratch("allowed");
    let root = dir.join("project");
    std::fs::create_dir_all(&root).unwrap();
    std::fs::write(dir.join("shared.yaml"), "subtrees:\n  s: {root: {home: {}}}\n").unwrap();
    let tree = root.join("t.yaml");
    std::fs::write(&tree, "include: [../shared.yaml]\nmain: {subtree: {ref: s}}\n").unwrap();
    assert_eq!(macrotree(&["validate", s(&tree)]).status.code(), Some(2));
    let out = macrotree(&["validate", "--allow-include-outside", s(&tree)]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A file that is not a tree — included, given as the main tree, or not named `.yaml` — gets
/// one diagnostic, located, that quotes nothing of it: not a line, not a key.
#[test]
fn a_file_that_is_not_a_tree_quotes_nothing_of_it() {
    let dir = scratch("not-a-tree");
    std::fs::write(dir.join("secret.yaml"), SECRET).unwrap();
    std::fs::write(
        dir.join("multi.txt"),
        "first-line-secret\nsecond-line-secret\nthird-line-secret\n",
    )
    .unwrap();
    // Not a tree, and a syntax error in a file not named `.yaml`: located, never quoted.
    std::fs::write(dir.join("env"), "TOKEN=s3cr3t-value-1\nx: [s3cr3t-value-2\n").unwrap();
    let secrets = [
        "api_token",
        "s3cr3t-value-1",
        "s3cr3t-value-2",
        "s3cr3t-value-3",
        "first-line",
        "second-line",
        "third-line",
    ];
    for include in ["secret.yaml", "multi.txt", "env"] {
        // Inside the tree folder, and outside it with the flag: the same rule.
        for (tree, flag) in [
            (tree_including(&dir, include), None),
            (
                tree_including(&dir.join("sub"), &format!("../{include}")),
                Some("--allow-include-outside"),
            ),
        ] {
            let mut args = vec!["validate", s(&tree)];
            args.extend(flag);
            let out = macrotree(&args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{stderr}");
            assert_eq!(
                stderr.matches("error: ").count(),
                2,
                "one diagnostic and the total: {stderr}"
            );
            assert!(stderr.contains(&format!("{include}:")), "located: {stderr}");
            for other in secrets {
                assert!(!stderr.contains(other), "{include}: showed {other:?}: {stderr}");
            }
        }
    }
    // The main file too, as a tree and as a scene.
    for file in ["secret.yaml", "multi.txt", "env"] {
        let path = dir.join(file);
        for args in [
            vec!["validate", s(&path)],
            vec!["run", "trees/cube_to_bowl.yaml", "--scene", s(&path)],
        ] {
            let out = macrotree(&args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{stderr}");
            for other in secrets {
                assert!(!stderr.contains(other), "{args:?} showed {other:?}: {stderr}");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
