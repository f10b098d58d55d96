//! The scene loader's fuzz target (`fuzz/fuzz_targets/load_scene.rs`, see docs/fuzzing.md): a
//! replay of its seeds through the target's own entry point, so that its code path runs in CI,
//! and the regressions fuzzing found. (No wall-clock assertions: a regressed hang would hang this
//! test, a regressed blow-up would abort it.)

use std::path::Path;

use macrotree::spec::Diagnostic;

use crate::scene_entry;
use crate::support::files;

fn repo_root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn assert_located(diags: &[Diagnostic], what: &str) {
    assert!(!diags.is_empty(), "{what}: an error without diagnostics");
    for d in diags {
        assert!(d.line >= 1 && d.column >= 1, "{what}: unlocated {d:?}");
        assert!(!d.message.is_empty(), "{what}: empty message {d:?}");
        assert!(d.file.ends_with(scene_entry::INPUT_NAME), "{what}: {d}");
    }
}

/// The ```yaml blocks of README.md and docs/*.md that are scenes (a top-level `objects:`), as
/// `fuzz/seed-corpus` picks them.
fn doc_scene_seeds() -> Vec<(String, String)> {
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
        let mut block: Option<String> = None;
        for line in text.lines() {
            match &mut block {
                None if line.starts_with("```yaml") => block = Some(String::new()),
                Some(body) if line.starts_with("```") => {
                    if body.starts_with("objects:") || body.contains("\nobjects:") {
                        out.push((format!("{stem} example"), std::mem::take(body)));
                    }
                    block = None;
                }
                Some(body) => {
                    body.push_str(line);
                    body.push('\n');
                }
                None => {}
            }
        }
    }
    out
}

#[test]
fn every_scene_seed_loads_through_the_fuzz_entry_point() {
    let mut seeds: Vec<(String, String)> = files::yaml_files(&repo_root().join("scenes"))
        .into_iter()
        .map(|p| {
            let rel = p.strip_prefix(repo_root()).unwrap().display().to_string();
            (rel, std::fs::read_to_string(&p).unwrap())
        })
        .collect();
    let from_docs = doc_scene_seeds();
    assert!(!from_docs.is_empty(), "no scene example in the docs");
    seeds.extend(from_docs);
    assert!(seeds.len() >= 5, "{} seeds", seeds.len());
    for (name, text) in &seeds {
        // Every seed is a valid scene: the fuzzer starts from inputs that reach the placement
        // checks, the sweep draw and the MJCF writer.
        let scene = scene_entry::load_scene(text.as_bytes())
            .unwrap_or_else(|d| panic!("{name}: {}", d.iter().map(|d| d.to_string()).collect::<String>()));
        assert!(!scene.objects.is_empty(), "{name}");
    }
}

#[test]
fn scene_fuzz_entry_locates_every_error() {
    for (what, text) in [
        ("empty", ""),
        ("not a mapping", "- 1\n"),
        ("unknown key", "objects: {}\nfloor: 1\n"),
        (
            "bad size",
            "objects:\n  a: {block: {size: 1e308}, pose: [0.45, 0]}\n",
        ),
        (
            "nan pose",
            "objects:\n  a: {block: {size: 0.04}, pose: [.nan, 0]}\n",
        ),
        (
            "unknown goal object",
            "objects:\n  a: {block: {size: 0.04}, pose: [0.45, 0]}\ngoal:\n  - in: {object: a, container: b}\n",
        ),
        (
            "unsatisfiable randomization",
            "objects:\n  a: {block: {size: 0.04}, random: {x: [0.45, 0.45], y: [0, 0]}}\n  b: {block: {size: 0.04}, random: {x: [0.45, 0.45], y: [0, 0]}}\n",
        ),
    ] {
        match scene_entry::load_scene(text.as_bytes()) {
            Ok(_) => panic!("{what}: loaded"),
            Err(d) => assert_located(&d, what),
        }
    }
}
