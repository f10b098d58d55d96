//! The crate's layers are true: every `crate::…` path in `src/` goes from a top-level module to
//! one of a lower layer, as the table in `src/lib.rs` states. A use that goes sideways or up — the
//! start of a cycle — fails here with the file and line that makes it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The layer of each top-level module, read from the table in `src/lib.rs`
/// (`//! | 4 | [`kinds`] | … |`).
fn layers(lib: &str) -> BTreeMap<String, u32> {
    let mut out = BTreeMap::new();
    for line in lib.lines() {
        let Some(row) = line.strip_prefix("//! |") else {
            continue;
        };
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let (Some(layer), Some(module)) = (cells.first(), cells.get(1)) else {
            continue;
        };
        let Ok(layer) = layer.parse::<u32>() else {
            continue;
        };
        let name = module.trim_matches(|c| "[]`".contains(c));
        out.insert(name.to_string(), layer);
    }
    out
}

/// The root re-exports of `src/lib.rs` (`pub use app::App;` → `App` is in `app`).
fn reexports(lib: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for line in lib.lines() {
        let Some(rest) = line.trim().strip_prefix("pub use ") else {
            continue;
        };
        let rest = rest.trim_end_matches(';');
        let Some((module, names)) = rest.split_once("::") else {
            continue;
        };
        for name in names.trim_matches(|c| c == '{' || c == '}').split(',') {
            let name = name.split(" as ").last().unwrap_or(name).trim();
            if !name.is_empty() {
                out.insert(name.to_string(), module.to_string());
            }
        }
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a line without its `//` comment (a `//` right after `:` is a URL, not a comment).
fn code(line: &str) -> &str {
    let mut from = 0;
    while let Some(i) = line[from..].find("//") {
        let at = from + i;
        if at > 0 && line.as_bytes()[at - 1] == b':' {
            from = at + 2;
            continue;
        }
        return &line[..at];
    }
    line
}

/// Every `crate::name` on a line of code, as the top-level module it names.
fn targets(code: &str, modules: &BTreeMap<String, u32>, reexports: &BTreeMap<String, String>) -> Vec<String> {
    let mut out = Vec::new();
    for (i, _) in code.match_indices("crate::") {
        if i > 0 && (code.as_bytes()[i - 1].is_ascii_alphanumeric() || code.as_bytes()[i - 1] == b'_') {
            continue; // `macrotree_crate::…`, not ours
        }
        let rest = &code[i + "crate::".len()..];
        let names: Vec<&str> = match rest.strip_prefix('{') {
            Some(group) => group
                .split('}')
                .next()
                .unwrap_or("")
                .split(',')
                .map(|n| n.trim().split("::").next().unwrap_or(""))
                .collect(),
            None => vec![
                rest.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                    .next()
                    .unwrap_or(""),
            ],
        };
        for name in names {
            if modules.contains_key(name) {
                out.push(name.to_string());
            } else if let Some(m) = reexports.get(name) {
                out.push(m.clone());
            }
        }
    }
    out
}

#[test]
fn every_crate_path_goes_to_a_lower_layer_as_lib_rs_states() {
    let src = Path::new(ROOT).join("src");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    let layer = layers(&lib);
    let reexports = reexports(&lib);
    assert!(
        layer.len() >= 20,
        "the layer table of src/lib.rs was not found: {layer:?}"
    );

    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut seen_modules = BTreeSet::new();
    let mut edges: BTreeMap<(String, String), String> = BTreeMap::new();
    for file in &files {
        let rel = file.strip_prefix(&src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy()
            .into_owned();
        let module = first.trim_end_matches(".rs").to_string();
        if matches!(module.as_str(), "lib" | "main") {
            continue;
        }
        seen_modules.insert(module.clone());
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            for target in targets(code(line), &layer, &reexports) {
                if target != module {
                    edges
                        .entry((module.clone(), target))
                        .or_insert_with(|| format!("src/{}:{}", rel.display(), n + 1));
                }
            }
        }
    }

    let unlisted: Vec<&String> = seen_modules.iter().filter(|m| !layer.contains_key(*m)).collect();
    assert!(
        unlisted.is_empty(),
        "top-level modules missing from the table in src/lib.rs: {unlisted:?}"
    );
    let stale: Vec<&String> = layer.keys().filter(|m| !seen_modules.contains(*m)).collect();
    assert!(
        stale.is_empty(),
        "the table in src/lib.rs names modules that do not exist: {stale:?}"
    );

    let wrong: Vec<String> = edges
        .iter()
        .filter(|((from, to), _)| layer[to] >= layer[from])
        .map(|((from, to), at)| {
            format!(
                "{from} (layer {}) uses {to} (layer {}) at {at}",
                layer[from], layer[to]
            )
        })
        .collect();
    assert!(
        wrong.is_empty(),
        "uses that go sideways or up (a module may only use lower layers):\n{}",
        wrong.join("\n")
    );
}

#[test]
fn the_census_sees_uses_in_every_form() {
    let modules: BTreeMap<String, u32> = [("spec", 5), ("kinds", 4), ("app", 12)]
        .into_iter()
        .map(|(m, l)| (m.to_string(), l))
        .collect();
    let reexports: BTreeMap<String, String> = [("App".to_string(), "app".to_string())].into();
    let t = |line: &str| targets(code(line), &modules, &reexports);
    assert_eq!(t("use crate::spec::Spec;"), ["spec"]);
    assert_eq!(t("use crate::{kinds::Leaf, spec};"), ["kinds", "spec"]);
    assert_eq!(t("fn f(a: &crate::App) {}"), ["app"]);
    assert_eq!(t("let x = 1; // crate::spec in a comment"), Vec::<String>::new());
    assert_eq!(t("let u = \"http://x\"; crate::kinds::f()"), ["kinds"]);
    assert_eq!(t("use crate::motion::HOME_Q;"), Vec::<String>::new()); // not in this table
}
