//! Regressions found while fuzzing the loader (`fuzz/`, see docs/fuzzing.md), and a replay of the
//! fuzz corpus seeds through the fuzz target's own entry point, so that its code path runs in CI.
//! (No wall-clock assertions: a regressed hang would hang this test, a regressed blow-up would
//! abort it.)

use std::path::{Path, PathBuf};

use macrotree::plan::Loader;
use macrotree::spec::Diagnostic;

use crate::entry;
use crate::support::files;

fn repo_root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The files `fuzz/seed-corpus` copies into the corpus: every `.yaml` under trees/ and
/// tests/fixtures/.
fn seed_files() -> Vec<PathBuf> {
    let mut out = files::yaml_files(&repo_root().join("trees"));
    out.extend(files::yaml_files(&repo_root().join("tests/fixtures")));
    out.sort();
    out
}

fn assert_located(diags: &[Diagnostic], what: &str) {
    assert!(!diags.is_empty(), "{what}: an error without diagnostics");
    for d in diags {
        assert!(d.line >= 1 && d.column >= 1, "{what}: unlocated {d:?}");
        assert!(!d.message.is_empty(), "{what}: empty message {d:?}");
    }
}

/// The other seeds of `fuzz/seed-corpus`: every ```yaml block of README.md and docs/*.md,
/// wrapped into a tree when it has no `main:` (`main:` + the node, or a `sequence` of the listed
/// nodes), as the script's awk does.
fn doc_seeds() -> Vec<(String, String)> {
    let mut docs = vec![repo_root().join("README.md")];
    for e in std::fs::read_dir(repo_root().join("docs")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "md") {
            docs.push(p);
        }
    }
    let mut out = Vec::new();
    for doc in docs {
        let text = std::fs::read_to_string(&doc).unwrap();
        let stem = doc.file_stem().unwrap().to_string_lossy().into_owned();
        let mut block: Option<Vec<&str>> = None;
        for line in text.lines() {
            match &mut block {
                None if line.starts_with("```yaml") => block = Some(Vec::new()),
                Some(lines) if line.starts_with("```") => {
                    out.push((format!("{stem} example {}", out.len() + 1), wrap(lines)));
                    block = None;
                }
                Some(lines) => lines.push(line),
                None => {}
            }
        }
    }
    out
}

fn wrap(lines: &[&str]) -> String {
    if lines.iter().any(|l| l.starts_with("main:")) {
        return lines.iter().map(|l| format!("{l}\n")).collect();
    }
    let first = lines
        .iter()
        .find(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (head, indent) = match first {
        Some(l) if l.starts_with("- ") => ("main:\n  sequence:\n    children:\n", "      "),
        _ => ("main:\n", "  "),
    };
    head.to_string() + &lines.iter().map(|l| format!("{indent}{l}\n")).collect::<String>()
}

#[test]
fn every_doc_example_replays_through_the_fuzz_entry_point() {
    let blocks = doc_seeds();
    assert!(blocks.len() >= 20, "{} yaml blocks", blocks.len());
    let mut ok = Vec::new();
    for (name, text) in &blocks {
        match entry::load_tree(text.as_bytes(), repo_root()) {
            Ok(_) => ok.push(name.as_str()),
            Err(d) => assert_located(&d, name),
        }
    }
    // Most examples are complete nodes: wrapped, they compile and seed the fuzzer with every
    // node kind.
    assert!(
        ok.len() >= blocks.len() / 2,
        "only {ok:?} of {} compile",
        blocks.len()
    );
}

#[test]
fn every_seed_replays_through_the_fuzz_entry_point() {
    let seeds = seed_files();
    assert!(seeds.len() >= 10, "seeds: {seeds:?}");
    let mut ok = Vec::new();
    for p in &seeds {
        let bytes = std::fs::read(p).unwrap();
        let rel = p.strip_prefix(repo_root()).unwrap().display().to_string();
        match entry::load_tree(&bytes, repo_root()) {
            Ok(plan) => {
                assert!(plan.behavior_size() > 0, "{rel}");
                ok.push(rel);
            }
            Err(d) => assert_located(&d, &rel),
        }
    }
    // The seeds that are complete trees compile under the fuzz input's name, so their
    // `include: [lib/pick_place.yaml]` resolves and the fuzzer starts from deep, valid inputs.
    for must in [
        "trees/cube_to_bowl.yaml",
        "tests/fixtures/trees/pick_place.yaml",
        "tests/fixtures/trees/include_cycle.yaml",
    ] {
        assert!(
            ok.iter().any(|r| r == must),
            "{must} does not compile: ok = {ok:?}"
        );
    }
}

#[test]
fn fuzz_entry_reports_bad_utf8_located() {
    let d = entry::load_tree(b"main:\n  home: {name: caf\xe9}\n", repo_root()).unwrap_err();
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(d[0].message.contains("not valid UTF-8"), "{}", d[0]);
    assert_eq!((d[0].line, d[0].column), (2, 19));
    assert!(d[0].file.ends_with("fuzz_input.yaml"), "{}", d[0].file);
}

/// The include tests below pin what the loader does with files outside the tree's folder when
/// includes may read anywhere (`--allow-include-outside`); by default such includes are refused
/// before they are opened (tests/tree/include_confinement.rs).
fn anywhere() -> Loader {
    Loader::default().includes_anywhere(true)
}

/// Bug (found reviewing what the fuzz target can reach): `include:` of a device was read to its
/// end. `/dev/zero` reports size 0, so the size check passed and the loader read until it ran out
/// of memory.
#[cfg(unix)]
#[test]
fn include_of_dev_zero_is_rejected_not_read() {
    let d = anywhere()
        .compile_bytes(b"include: [/dev/zero]\nmain: {home: {}}\n", "t.yaml")
        .unwrap_err();
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(d[0].message, "`/dev/zero` is not a regular file");
    assert_eq!((d[0].line, d[0].column), (1, 11));
}

/// Bug (same review): `include:` of a FIFO blocked forever waiting for a writer.
#[cfg(unix)]
#[test]
fn include_of_a_fifo_does_not_block() {
    let dir = std::env::temp_dir().join(format!("macrotree-fuzz-fifo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("pipe.yaml");
    let _ = std::fs::remove_file(&fifo);
    let status = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(status.success(), "mkfifo failed");
    let src = format!("include: [{}]\nmain: {{home: {{}}}}\n", fifo.display());
    let d = anywhere().compile_bytes(src.as_bytes(), "t.yaml").unwrap_err();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(d[0].message.ends_with("is not a regular file"), "{}", d[0]);
    assert_eq!((d[0].line, d[0].column), (1, 11));
}

/// Bug (same review): a regular file whose reported size is 0 but whose content is endless
/// (`/proc/self/pagemap` has 8 bytes per page of address space) passed the size check and was
/// read whole. Reads now stop one byte past the 1 MiB limit; pagemap then refuses that last
/// 1-byte read (it serves whole 8-byte entries), which is reported as an unreadable file.
#[cfg(target_os = "linux")]
#[test]
fn include_of_an_endless_proc_file_stops_at_the_size_limit() {
    let pagemap = Path::new("/proc/self/pagemap");
    assert!(pagemap.is_file(), "/proc/self/pagemap is missing");
    let d = anywhere()
        .compile_bytes(b"include: [/proc/self/pagemap]\nmain: {home: {}}\n", "t.yaml")
        .unwrap_err();
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(
        d[0].message == "file is too large: more than 1048576 bytes (limit 1048576 bytes)"
            || d[0].message.starts_with("cannot read `/proc/self/pagemap`"),
        "{}",
        d[0]
    );
    assert_eq!((d[0].line, d[0].column), (1, 11));
}
