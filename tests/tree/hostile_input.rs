//! Hostile or broken input gives a clean, located error — never a panic, a hang or a blow-up.
//! (No wall-clock assertions: limits are asserted on sizes.)

use std::path::PathBuf;

use macrotree::plan::Loader;
use macrotree::spec::Diagnostic;

fn errors(src: &str) -> Vec<Diagnostic> {
    match Loader::default().compile_str(src, "hostile.yaml") {
        Ok(_) => panic!("expected an error"),
        Err(d) => d,
    }
}

fn temp_file(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("macrotree-tree-robustness-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn empty_file() {
    let d = errors("");
    assert_eq!(d.len(), 1);
    assert_eq!(d[0].message, "the file is empty");
    assert_eq!((d[0].line, d[0].column), (1, 1));
    let d = errors("\n\n# comment only\n");
    assert_eq!(d[0].message, "the file is empty");
}

#[test]
fn alias_bomb() {
    // Billion laughs: 10 levels of 10 aliases each would expand to 10^10 nodes.
    let mut s = String::from("a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n");
    for i in 1..10 {
        let p = i - 1;
        s.push_str(&format!(
            "a{i}: &a{i} [*a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}]\n"
        ));
    }
    s.push_str("main: {home: {}}\n");
    let d = errors(&s);
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(
        d[0].message,
        "the YAML holds more than 100000 values once aliases are expanded"
    );
    assert!(
        d[0].help.as_deref().is_some_and(|h| h.contains("subtree")),
        "{}",
        d[0]
    );
    assert!(d[0].line >= 1);
}

#[test]
fn a_million_byte_list_is_refused_by_its_value_count() {
    let src = format!("main: {{home: {{}}}}\nx: [{}]\n", vec!["1"; 340_000].join(", "));
    let d = errors(&src);
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(
        d[0].message.starts_with("the YAML holds more than 100000 values"),
        "{}",
        d[0]
    );
    // The error sits deep in one long line; the shown source is a window, not the whole line.
    assert!(d[0].to_string().len() < 1_000, "{} bytes", d[0].to_string().len());
}

#[test]
fn two_yaml_documents_in_one_file() {
    let d = errors("main: {home: {}}\n---\nmain: {home: {}}\n");
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(
        d[0].message.starts_with("a tree file holds one YAML document"),
        "{}",
        d[0]
    );
    assert_eq!(d[0].line, 2);
}

#[test]
fn very_deep_nesting() {
    for (src, expected) in [
        ("[".repeat(100_000), "nested"),
        ("{a: ".repeat(100_000), "nested"),
        ("- ".repeat(100_000) + "x", "nested"),
        // 2.3 MB: refused by size before the parser sees it.
        (
            format!("main: {}", "{sequence: {children: [".repeat(100_000)),
            "file is too large",
        ),
        (
            format!("main: {}", "{sequence: {children: [".repeat(40_000)),
            "nested",
        ),
    ] {
        let d = errors(&src);
        assert_eq!(d.len(), 1, "{d:?}");
        assert!(d[0].message.contains(expected), "{}", d[0]);
        assert!(d[0].line >= 1, "{}", d[0]);
    }
}

#[test]
fn deep_but_valid_yaml_hits_the_tree_depth_limit() {
    let mut src = String::from("main: ");
    for _ in 0..70 {
        src.push_str("{inverter: {child: ");
    }
    src.push_str("{home: {}}");
    for _ in 0..70 {
        src.push_str("}}");
    }
    let d = errors(&src);
    assert!(
        d.iter().any(|d| d.message.contains("nested more than 64 levels")),
        "{d:?}"
    );
}

#[test]
fn exponential_subtree_expansion_is_capped() {
    // Each level calls the previous one twice: 2^20 leaves if unchecked.
    let mut src = String::from("subtrees:\n  s0: {root: {home: {}}}\n");
    for i in 1..=20 {
        let p = i - 1;
        src.push_str(&format!(
            "  s{i}: {{root: {{sequence: {{children: [{{subtree: {{ref: s{p}}}}}, {{subtree: {{ref: s{p}}}}}]}}}}}}\n"
        ));
    }
    src.push_str("main: {subtree: {ref: s20}}\n");
    let d = errors(&src);
    assert!(
        d.iter().any(|d| d.message.contains("more than 5000 nodes")),
        "{d:?}"
    );
}

/// Retry and repeat keep their counts in the runtime: nested loops of a thousand attempts each
/// compile to a handful of bonsai nodes (they used to copy the child per attempt, a million
/// copies here, and needed a cap).
#[test]
fn nested_retries_compile_without_copies() {
    let src = "main: {retry: {attempts: 1000, child: {repeat: {times: 1000, child: {home: {}}}}}}";
    let plan = macrotree::plan::Loader::default()
        .compile_str(src, "t.yaml")
        .expect("compiles");
    assert!(plan.behavior_size() < 40, "{} bonsai nodes", plan.behavior_size());
}

#[test]
fn binary_garbage() {
    // A deterministic pseudo-random byte soup, lossily made into text.
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let bytes: Vec<u8> = (0..4096)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 24) as u8
        })
        .collect();
    let p = temp_file("garbage.yaml", &bytes);
    let d = Loader::default().load(&p).unwrap_err();
    assert_eq!(d.len(), 1);
    assert!(d[0].message.contains("not valid UTF-8"), "{}", d[0]);
    let text = String::from_utf8_lossy(&bytes);
    let d = errors(&text);
    assert!(!d.is_empty());
    for diag in &d {
        let shown = diag.to_string();
        assert!(
            !shown.chars().any(|c| c.is_control() && c != '\n'),
            "control characters in {shown:?}"
        );
    }
}

#[test]
fn non_utf8_is_located() {
    let p = temp_file("latin1.yaml", b"main:\n  reach: {target: caf\xe9}\n");
    let d = Loader::default().load(&p).unwrap_err();
    assert_eq!(d.len(), 1);
    assert!(d[0].message.contains("not valid UTF-8"), "{}", d[0]);
    assert_eq!((d[0].line, d[0].column), (2, 22));
}

#[test]
fn a_leaf_with_thousands_of_bad_keys_reports_a_capped_number() {
    // Each reported error re-reads the leaf; the cap keeps this linear in the file size.
    let keys: Vec<String> = (0..20_000).map(|i| format!("k{i}: 1")).collect();
    let d = errors(&format!("main:\n  home: {{{}}}\n", keys.join(", ")));
    assert_eq!(d.len(), macrotree::spec::MAX_LEAF_ERRORS, "{}", d[0]);
    assert!(d.iter().all(|e| e.message.starts_with("unknown parameter `k")));
}

#[test]
fn fifty_megabyte_file_is_rejected_before_parsing() {
    let size = 50 * 1024 * 1024;
    let mut big = String::with_capacity(size + 32);
    big.push_str("main: {home: {}}\n");
    while big.len() < size {
        big.push_str("# padding padding padding padding padding padding padding padding\n");
    }
    let d = errors(&big);
    assert_eq!(d.len(), 1);
    assert!(d[0].message.starts_with("file is too large"), "{}", d[0]);
    let p = temp_file("big.yaml", big.as_bytes());
    let d = Loader::default().load(&p).unwrap_err();
    assert!(d[0].message.starts_with("file is too large"), "{}", d[0]);
    let _ = std::fs::remove_file(p);
}

#[test]
fn missing_file_and_folder() {
    let d = Loader::default()
        .load(std::path::Path::new("tests/fixtures/trees/does_not_exist.yaml"))
        .unwrap_err();
    assert!(d[0].message.starts_with("cannot read"), "{}", d[0]);
    let d = Loader::default()
        .load(std::path::Path::new("tests/fixtures/trees"))
        .unwrap_err();
    assert!(d[0].message.contains("is a folder"), "{}", d[0]);
}

/// Every prefix of a valid file, and many single-byte corruptions of it, either compile or give
/// located diagnostics (no panic).
#[test]
fn truncations_and_corruptions_never_panic() {
    let src = std::fs::read_to_string("tests/fixtures/trees/lib/pick_place.yaml").unwrap()
        + "main: {subtree: {ref: pick, args: {approach: 0.1}}}\n";
    let bytes = src.as_bytes();
    for cut in 0..bytes.len() {
        let Ok(prefix) = std::str::from_utf8(&bytes[..cut]) else {
            continue;
        };
        if let Err(d) = Loader::default().compile_str(prefix, "cut.yaml") {
            assert!(d.iter().all(|d| d.line >= 1), "{d:?}");
        }
    }
    let replacements = b"{}[]:-,$&*!|>'\"# \n\t0a~";
    let mut x: u32 = 12345;
    for _ in 0..3000 {
        x = x.wrapping_mul(1_103_515_245).wrapping_add(12_345);
        let pos = (x >> 8) as usize % bytes.len();
        let ch = replacements[(x >> 20) as usize % replacements.len()];
        let mut b = bytes.to_vec();
        b[pos] = ch;
        if let Ok(s) = std::str::from_utf8(&b)
            && let Err(d) = Loader::default().compile_str(s, "mutant.yaml")
        {
            assert!(!d.is_empty());
        }
    }
}
