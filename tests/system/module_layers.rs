//! The crate's layers are true: every `crate::…` path in `src/` goes from a top-level module to
//! one of a lower layer, as the table in `src/lib.rs` states. A use that goes sideways or up — the
//! start of a cycle — fails here with the file and line that makes it.
//!
//! Inside every module, too, the files and folders beside each other (its child modules) use
//! each other without a cycle: a `super::…`, `self::…` or `crate::…` path in one child that names
//! another is an edge, and a cycle fails with the file and line of each of its edges.

use std::collections::{BTreeMap, BTreeSet, VecDeque};
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

// Inside each module: its children (files and folders) use each other without a cycle.

/// A module's path below the crate root (`["motion", "plan"]`); the root is empty.
type ModPath = Vec<String>;

/// The uses between the children of one module: (user, used) → the first `file:line` of one.
type Edges = BTreeMap<(String, String), String>;

/// A cycle of uses, each step as (user, used, `file:line`).
type Cycle = Vec<(String, String, String)>;

/// How a written path starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Start {
    /// `crate::`
    Crate,
    /// `super::`, this many times.
    Super(usize),
    /// `self::`
    SelfMod,
}

/// A path written in the code: the line it starts on (0-based), how it starts, and the names
/// after that start (`super::b::C` → `Super(1)`, `["b", "C"]`).
#[derive(Debug, PartialEq)]
struct Written {
    line: usize,
    start: Start,
    names: Vec<String>,
}

/// A name as Rust spells one: letters, digits and `_`.
fn is_ident(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The module a line declares (`mod tests;`, `pub(crate) mod a {`), and whether its body
/// follows inline (`{`).
fn mod_declaration(line: &str) -> Option<(&str, bool)> {
    let mut rest = line.trim();
    for visibility in ["pub(crate) ", "pub(super) ", "pub "] {
        if let Some(r) = rest.strip_prefix(visibility) {
            rest = r;
            break;
        }
    }
    let rest = rest.strip_prefix("mod ")?;
    let (name, inline) = match rest.strip_suffix(';') {
        Some(name) => (name, false),
        None => (rest.strip_suffix(" {")?, true),
    };
    is_ident(name).then_some((name, inline))
}

/// The modules `text` takes from another file (`#[path = "x_tests.rs"] mod tests;`), as the
/// file's name and the module's.
fn path_attributes(text: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut file: Option<String> = None;
    for line in text.lines().map(str::trim) {
        if let Some(rest) = line.strip_prefix("#[path = \"") {
            file = rest.split('"').next().map(str::to_string);
        } else if line.starts_with("#[") {
            continue; // another attribute of the same declaration
        } else if let Some(f) = file.take()
            && let Some((name, false)) = mod_declaration(line)
        {
            out.push((f, name.to_string()));
        }
    }
    out
}

/// The module `file` is by its place under `src` (`a/b.rs` and `a/b/mod.rs` are `a::b`); `None`
/// for the crate roots `lib.rs` and `main.rs`.
fn module_of(src: &Path, file: &Path) -> Option<ModPath> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut path: ModPath = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if path == ["lib"] || path == ["main"] {
        return None;
    }
    if path.last().is_some_and(|last| last == "mod") {
        path.pop();
    }
    Some(path)
}

/// The module of every file under `src` but the crate roots: by its place, or, for a file taken
/// in with `#[path = "…"]`, the module that declares it.
fn file_modules(src: &Path, files: &[PathBuf]) -> BTreeMap<PathBuf, ModPath> {
    let mut out: BTreeMap<PathBuf, ModPath> = files
        .iter()
        .filter_map(|f| Some((f.clone(), module_of(src, f)?)))
        .collect();
    for file in files {
        let Some(declaring) = module_of(src, file) else {
            continue;
        };
        for (name, module) in path_attributes(&std::fs::read_to_string(file).unwrap()) {
            let mut path = declaring.clone();
            path.push(module);
            out.insert(file.parent().unwrap().join(name), path);
        }
    }
    out
}

/// For each line of `code`, the inline modules (`mod tests { … }`) it lies in, outermost first,
/// as rustfmt lays them out: `mod name {` opens one and a `}` at its indentation closes it.
fn inline_modules(code: &str) -> Vec<Vec<String>> {
    let mut open: Vec<(String, usize)> = Vec::new();
    let mut out = Vec::new();
    for line in code.lines() {
        out.push(open.iter().map(|(name, _)| name.clone()).collect());
        let indent = line.len() - line.trim_start().len();
        if let Some((name, true)) = mod_declaration(line) {
            open.push((name.to_string(), indent));
        } else if line.trim() == "}" && open.last().is_some_and(|&(_, i)| i == indent) {
            open.pop();
        }
    }
    out
}

/// How `text` starts a path — `crate::`, `self::` or one or more `super::` — and what follows.
fn path_start(text: &str) -> Option<(Start, &str)> {
    if let Some(rest) = text.strip_prefix("crate::") {
        return Some((Start::Crate, rest));
    }
    if let Some(rest) = text.strip_prefix("self::") {
        return Some((Start::SelfMod, rest));
    }
    let mut rest = text;
    let mut n = 0;
    while let Some(r) = rest.strip_prefix("super::") {
        rest = r;
        n += 1;
    }
    (n > 0).then_some((Start::Super(n), rest))
}

/// The items of a group, `text` starting just inside its `{`: split at its top-level commas, up
/// to its `}` (empty items, after a trailing comma, left out).
fn group_items(text: &str) -> Vec<&str> {
    let mut items = Vec::new();
    let (mut depth, mut from) = (0, 0);
    for (i, c) in text.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => {
                items.push(&text[from..i]);
                break;
            }
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(&text[from..i]);
                from = i + 1;
            }
            _ => {}
        }
    }
    items.retain(|item| !item.trim().is_empty());
    items
}

/// The paths a use tree (or a path in code) gives: `a::b` → `[a, b]`; `{a, b::{c, D}}` → `[a]`,
/// `[b, c]`, `[b, D]`; `*`, `self` or `<T>` end a path where it is.
fn use_tree(text: &str) -> Vec<Vec<String>> {
    let text = text.trim_start();
    if let Some(group) = text.strip_prefix('{') {
        return group_items(group).into_iter().flat_map(use_tree).collect();
    }
    let len = text
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(text.len());
    let name = &text[..len];
    if name.is_empty() || name == "self" {
        return vec![Vec::new()];
    }
    match text[len..].strip_prefix("::") {
        Some(rest) => use_tree(rest)
            .into_iter()
            .map(|tail| std::iter::once(name.to_string()).chain(tail).collect())
            .collect(),
        None => vec![vec![name.to_string()]],
    }
}

/// Every `crate::…`, `super::…` and `self::…` path in `code` (its comments removed), in imports
/// and in code alike; a grouped import gives one path per item, across lines too
/// (`use super::{a, b::C};` → `a` and `b::C`, both at the line of `use`).
fn written_paths(code: &str) -> Vec<Written> {
    let mut out = Vec::new();
    let bytes = code.as_bytes();
    for (i, _) in code.char_indices() {
        let before = i.checked_sub(1).map(|j| bytes[j]);
        if before.is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b':') {
            continue; // `macrotree_crate::…`, or the second `super` of `super::super::…`
        }
        let Some((start, rest)) = path_start(&code[i..]) else {
            continue;
        };
        let line = code[..i].matches('\n').count();
        for names in use_tree(rest) {
            out.push(Written { line, start, names });
        }
    }
    out
}

/// The module path a written path names from inside module `here` (`None`: above the root).
fn resolve(here: &[String], start: Start, names: &[String]) -> Option<ModPath> {
    let base = match start {
        Start::Crate => &here[..0],
        Start::SelfMod => here,
        Start::Super(n) => &here[..here.len().checked_sub(n)?],
    };
    Some(base.iter().chain(names).cloned().collect())
}

/// The use a path from module `from` to `to` makes between siblings: in the innermost module
/// holding both, the child `from` lies in uses the child `to` names — when that child is one of
/// `modules`, not an item of the parent. Answers (parent, user, used).
fn sibling_edge(
    from: &[String],
    to: &[String],
    modules: &BTreeSet<ModPath>,
) -> Option<(ModPath, String, String)> {
    let k = from.iter().zip(to).take_while(|(a, b)| a == b).count();
    let (user, used) = (from.get(k)?, to.get(k)?);
    modules
        .contains(&to[..=k])
        .then(|| (from[..k].to_vec(), user.clone(), used.clone()))
}

/// For every module of the crate under `src`, the uses between its children.
fn sibling_graphs(src: &Path) -> BTreeMap<ModPath, Edges> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let by_file = file_modules(src, &files);
    let modules: BTreeSet<ModPath> = by_file.values().cloned().collect();
    let mut graphs: BTreeMap<ModPath, Edges> = BTreeMap::new();
    for (file, module) in &by_file {
        let text = std::fs::read_to_string(file).unwrap();
        let stripped = text.lines().map(code).collect::<Vec<_>>().join("\n");
        let inline = inline_modules(&stripped);
        for w in written_paths(&stripped) {
            let here: ModPath = module.iter().chain(&inline[w.line]).cloned().collect();
            let Some(to) = resolve(&here, w.start, &w.names) else {
                continue;
            };
            if let Some((parent, user, used)) = sibling_edge(module, &to, &modules) {
                let at = format!("src/{}:{}", file.strip_prefix(src).unwrap().display(), w.line + 1);
                graphs
                    .entry(parent)
                    .or_default()
                    .entry((user, used))
                    .or_insert(at);
            }
        }
    }
    graphs
}

/// The children reachable from `start` along `edges`.
fn reachable(start: &str, edges: &Edges) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut todo = vec![start.to_string()];
    while let Some(at) = todo.pop() {
        for (user, used) in edges.keys() {
            if *user == at && seen.insert(used.clone()) {
                todo.push(used.clone());
            }
        }
    }
    seen
}

/// The shortest way from `start` back to itself through `set`, as (user, used, `file:line`).
fn shortest_cycle(start: &str, set: &BTreeSet<String>, edges: &Edges) -> Cycle {
    let mut reached_by: BTreeMap<&str, &(String, String)> = BTreeMap::new();
    let mut queue = VecDeque::from([start]);
    'search: while let Some(at) = queue.pop_front() {
        for edge @ (user, used) in edges.keys() {
            if user != at || !set.contains(used) || reached_by.contains_key(used.as_str()) {
                continue;
            }
            reached_by.insert(used.as_str(), edge);
            if used == start {
                break 'search;
            }
            queue.push_back(used.as_str());
        }
    }
    let mut cycle = Vec::new();
    let mut at = start;
    loop {
        let edge = reached_by[at];
        cycle.push((edge.0.clone(), edge.1.clone(), edges[edge].clone()));
        at = &edge.0;
        if at == start {
            break;
        }
    }
    cycle.reverse();
    cycle
}

/// Each set of two or more children that reach each other, with one cycle through it.
fn cycles(edges: &Edges) -> Vec<(BTreeSet<String>, Cycle)> {
    let users: BTreeSet<&String> = edges.keys().map(|(user, _)| user).collect();
    let reach: BTreeMap<&String, BTreeSet<String>> =
        users.iter().map(|&u| (u, reachable(u, edges))).collect();
    let mut seen = BTreeSet::new();
    let mut out = Vec::new();
    for &child in &users {
        if seen.contains(child) || !reach[child].contains(child) {
            continue;
        }
        let set: BTreeSet<String> = users
            .iter()
            .filter(|&&other| reach[child].contains(other) && reach[other].contains(child))
            .map(|&other| other.clone())
            .collect();
        seen.extend(set.iter().cloned());
        let cycle = shortest_cycle(child, &set, edges);
        out.push((set, cycle));
    }
    out
}

#[test]
fn no_module_imports_its_siblings_in_a_cycle() {
    let src = Path::new(ROOT).join("src");
    let graphs = sibling_graphs(&src);
    let uses: usize = graphs.values().map(BTreeMap::len).sum();
    assert!(
        uses >= 300,
        "only {uses} uses between sibling modules found: the census no longer reads src/"
    );
    let mut found = Vec::new();
    for (parent, edges) in &graphs {
        let parent = if parent.is_empty() {
            "crate".to_string()
        } else {
            format!("crate::{}", parent.join("::"))
        };
        for (set, cycle) in cycles(edges) {
            let set: Vec<&str> = set.iter().map(String::as_str).collect();
            let mut names: Vec<&str> = cycle.iter().map(|(user, _, _)| user.as_str()).collect();
            names.push(cycle[0].0.as_str());
            let mut text = format!(
                "in {parent}, {} use each other; one cycle: {}",
                set.join(", "),
                names.join(" → ")
            );
            for (user, used, at) in &cycle {
                text += &format!("\n    {user} uses {used} at {at}");
            }
            found.push(text);
        }
    }
    assert!(
        found.is_empty(),
        "sibling modules that use each other in a cycle (move what closes it to where it belongs, \
         usually down into the file that uses it or a small file of its own):\n{}",
        found.join("\n")
    );
}

#[test]
fn the_sibling_census_reads_paths_in_every_form() {
    let paths = |text: &str| -> Vec<(usize, Start, String)> {
        let stripped = text.lines().map(code).collect::<Vec<_>>().join("\n");
        written_paths(&stripped)
            .into_iter()
            .map(|w| (w.line, w.start, w.names.join("::")))
            .collect()
    };
    let at = |line: usize, start: Start, path: &str| (line, start, path.to_string());
    assert_eq!(paths("use super::b::C;"), [at(0, Start::Super(1), "b::C")]);
    assert_eq!(
        paths("use super::{a, b::C};"),
        [at(0, Start::Super(1), "a"), at(0, Start::Super(1), "b::C")]
    );
    assert_eq!(
        paths("use crate::m::{\n    n::{o, P},\n    self,\n};"),
        [
            at(0, Start::Crate, "m::n::o"),
            at(0, Start::Crate, "m::n::P"),
            at(0, Start::Crate, "m")
        ]
    );
    assert_eq!(
        paths("let x = 1;\nlet y = super::super::x::f(2);"),
        [at(1, Start::Super(2), "x::f")]
    );
    assert_eq!(paths("pub use self::b::C;"), [at(0, Start::SelfMod, "b::C")]);
    assert_eq!(paths("fn f(a: &crate::a::B) {}"), [at(0, Start::Crate, "a::B")]);
    assert_eq!(paths("use super::*;"), [at(0, Start::Super(1), "")]);
    assert!(paths("f(); // super::b::g() in a comment").is_empty());
    assert!(paths("/// [`super::b`] in a doc comment").is_empty());
    assert!(paths("macrotree_crate::a::f(); my_super::b::g();").is_empty());

    // Resolved from where they are written, and kept when they name a sibling module.
    let modules: BTreeSet<ModPath> = [vec!["a"], vec!["a", "b"], vec!["a", "c"], vec!["a", "c", "d"]]
        .into_iter()
        .map(|m| m.into_iter().map(String::from).collect())
        .collect();
    let m = |s: &str| -> ModPath {
        s.split("::")
            .filter(|n| !n.is_empty())
            .map(String::from)
            .collect()
    };
    let edge = |from: &str, start: Start, names: &str| {
        let to = resolve(&m(from), start, &m(names))?;
        sibling_edge(&m(from), &to, &modules).map(|(parent, user, used)| (parent.join("::"), user, used))
    };
    let some =
        |parent: &str, user: &str, used: &str| Some((parent.to_string(), user.to_string(), used.to_string()));
    assert_eq!(edge("a::b", Start::Super(1), "c::X"), some("a", "b", "c"));
    assert_eq!(edge("a::c::d", Start::Super(2), "b::f"), some("a", "c", "b"));
    assert_eq!(edge("a::b", Start::Crate, "a::c"), some("a", "b", "c"));
    assert_eq!(
        edge("a", Start::SelfMod, "b"),
        None,
        "a parent's own file is not a sibling"
    );
    assert_eq!(
        edge("a::b", Start::Super(1), "helper"),
        None,
        "an item, not a module"
    );
    assert_eq!(edge("a::b", Start::Super(3), "x"), None, "above the root");

    // `super` inside an inline `mod tests` is the file's own module.
    let inline = inline_modules("fn f() {}\n#[cfg(test)]\nmod tests {\n    use super::c;\n}\nfn g() {}");
    assert_eq!(inline[3], ["tests"]);
    assert!(inline[5].is_empty());
    assert_eq!(
        path_attributes("#[cfg(test)]\n#[path = \"x_tests.rs\"]\nmod tests;"),
        [("x_tests.rs".to_string(), "tests".to_string())]
    );

    // A cycle is found, and reported through its own edges only.
    let edges: Edges = [
        ("a", "b", "a.rs:1"),
        ("b", "c", "b.rs:2"),
        ("c", "a", "c.rs:3"),
        ("c", "d", "c.rs:4"),
    ]
    .into_iter()
    .map(|(user, used, at)| ((user.into(), used.into()), at.into()))
    .collect();
    let found = cycles(&edges);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, ["a", "b", "c"].map(String::from).into());
    let steps: Vec<String> = found[0]
        .1
        .iter()
        .map(|(u, v, at)| format!("{u}>{v}@{at}"))
        .collect();
    assert_eq!(steps, ["a>b@a.rs:1", "b>c@b.rs:2", "c>a@c.rs:3"]);
}
