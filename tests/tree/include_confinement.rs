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

#[test]
fn a_file_that_is_not_a_tree_shows_at_most_one_line() {
    let dir = scratch("not-a-tree");
    std::fs::write(dir.join("secret.yaml"), SECRET).unwrap();
    std::fs::write(
        dir.join("multi.txt"),
        "first line of text\nsecond-line-secret\nthird-line-secret\n",
    )
    .unwrap();
    for (include, first) in [("secret.yaml", "s3cr3t-value-1"), ("multi.txt", "first line")] {
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
            assert!(stderr.contains(first), "the offending line is shown: {stderr}");
            for other in ["s3cr3t-value-2", "s3cr3t-value-3", "second-line", "third-line"] {
                assert!(!stderr.contains(other), "{include}: showed {other:?}: {stderr}");
            }
        }
    }
    // The main file too.
    let out = macrotree(&["validate", s(&dir.join("secret.yaml"))]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        !stderr.contains("s3cr3t-value-2") && !stderr.contains("s3cr3t-value-3"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
