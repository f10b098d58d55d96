//! A generic YAML value tree in which every node remembers where it came from.
//!
//! Tree files are first read into this form (with serde-saphyr and hard resource limits), so
//! that `$param` substitution in subtrees can happen *before* typed deserialization while every
//! value keeps its own file:line:column. Typed parameters are then read from it with
//! [`crate::yaml::de`].

use std::fmt;

use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_saphyr::Spanned;

use super::diag::{FileId, Issue, Loc};

/// Largest tree file accepted, in bytes. Real trees are a few kB; this keeps a stray 50 MB file
/// from being parsed at all.
pub const MAX_FILE_BYTES: usize = 1024 * 1024;

/// Deepest YAML nesting (mappings + sequences) accepted. One behavior-tree level costs about
/// four YAML levels (`sequence:` map, its body map, `children:` list, child map).
pub const MAX_YAML_DEPTH: usize = 160;

/// Most YAML nodes (scalars + collections) in one file, after alias expansion.
pub const MAX_YAML_NODES: usize = 100_000;

/// A YAML value with its source location.
#[derive(Clone, Debug, PartialEq)]
pub struct Value {
    /// The value.
    pub kind: ValueKind,
    /// Where it was written.
    pub loc: Loc,
    /// For values substituted from a subtree `$param`: the location of the `$param` use.
    pub via: Option<Loc>,
}

/// The shape of a [`Value`].
#[derive(Clone, Debug, PartialEq)]
pub enum ValueKind {
    /// `~`, `null` or an empty value.
    Null,
    /// `true` / `false`.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A float (also integers too large for `i64`).
    Float(f64),
    /// Any other scalar.
    Str(String),
    /// A sequence.
    Seq(Vec<Value>),
    /// A mapping, in source order (keys are values too; tree files only use string keys).
    Map(Vec<(Value, Value)>),
}

impl Value {
    /// A value at `loc`.
    pub fn new(kind: ValueKind, loc: Loc) -> Self {
        Self { kind, loc, via: None }
    }

    /// The string, if this is a string scalar.
    pub fn as_str(&self) -> Option<&str> {
        match &self.kind {
            ValueKind::Str(s) => Some(s),
            _ => None,
        }
    }

    /// The entries, if this is a mapping.
    pub fn as_map(&self) -> Option<&[(Value, Value)]> {
        match &self.kind {
            ValueKind::Map(m) => Some(m),
            _ => None,
        }
    }

    /// The items, if this is a sequence.
    pub fn as_seq(&self) -> Option<&[Value]> {
        match &self.kind {
            ValueKind::Seq(s) => Some(s),
            _ => None,
        }
    }

    /// Look a string key up in a mapping.
    pub fn get(&self, key: &str) -> Option<&Value> {
        self.as_map()?
            .iter()
            .find(|(k, _)| k.as_str() == Some(key))
            .map(|(_, v)| v)
    }

    /// Where the value under the mapping keys `path` is (the deepest one present; the value's
    /// own location when even the first is absent), for located issues.
    pub fn loc_at(&self, path: &[&str]) -> Loc {
        let mut cur = self;
        for k in path {
            match cur.get(k) {
                Some(next) => cur = next,
                None => break,
            }
        }
        cur.loc
    }

    /// A short description of the value's type for messages ("a mapping", "the string `x`").
    pub fn describe(&self) -> String {
        match &self.kind {
            ValueKind::Null => "null".into(),
            ValueKind::Bool(b) => format!("the boolean `{b}`"),
            ValueKind::Int(i) => format!("the integer `{i}`"),
            ValueKind::Float(x) => format!("the number `{x}`"),
            ValueKind::Str(s) => {
                let short: String = s.chars().take(40).collect();
                format!("the string `{short}`")
            }
            ValueKind::Seq(_) => "a list".into(),
            ValueKind::Map(_) => "a mapping".into(),
        }
    }

    /// Number of YAML nodes in this value (itself included).
    pub fn node_count(&self) -> usize {
        1 + match &self.kind {
            ValueKind::Seq(s) => s.iter().map(Value::node_count).sum(),
            ValueKind::Map(m) => m.iter().map(|(k, v)| k.node_count() + v.node_count()).sum(),
            _ => 0,
        }
    }

    fn set_file(&mut self, file: FileId) {
        self.loc.file = file;
        match &mut self.kind {
            ValueKind::Seq(s) => s.iter_mut().for_each(|v| v.set_file(file)),
            ValueKind::Map(m) => m.iter_mut().for_each(|(k, v)| {
                k.set_file(file);
                v.set_file(file);
            }),
            _ => {}
        }
    }
}

fn loc_of(l: &serde_saphyr::Location) -> Loc {
    Loc {
        file: 0,
        line: u32::try_from(l.line()).unwrap_or(u32::MAX),
        col: u32::try_from(l.column()).unwrap_or(u32::MAX),
        len: u32::try_from(l.span().len()).unwrap_or(u32::MAX),
    }
}

/// Deserialization target used only while reading: the kind, whose children are spanned.
struct RawKind(ValueKind);

fn spanned_to_value(s: Spanned<RawKind>) -> Value {
    let mut loc = loc_of(&s.referenced);
    // The parser spans a collection by its first character; one written on a single line
    // (`offset: [0, 0, 0.1]`) is underlined whole, through its closing bracket.
    let last = match &s.value.0 {
        ValueKind::Seq(items) => items.last(),
        ValueKind::Map(entries) => entries.last().map(|(_, v)| v),
        _ => None,
    };
    if let Some(last) = last
        && last.loc.line == loc.line
        && last.loc.col > loc.col
    {
        loc.len = last
            .loc
            .col
            .saturating_add(last.loc.len)
            .saturating_add(1)
            .saturating_sub(loc.col);
    }
    Value::new(s.value.0, loc)
}

impl<'de> Deserialize<'de> for RawKind {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(RawVisitor)
    }
}

struct RawVisitor;

impl<'de> Visitor<'de> for RawVisitor {
    type Value = RawKind;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("any YAML value")
    }
    fn visit_bool<E: de::Error>(self, v: bool) -> Result<RawKind, E> {
        Ok(RawKind(ValueKind::Bool(v)))
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<RawKind, E> {
        Ok(RawKind(ValueKind::Int(v)))
    }
    fn visit_i128<E: de::Error>(self, v: i128) -> Result<RawKind, E> {
        Ok(RawKind(match i64::try_from(v) {
            Ok(i) => ValueKind::Int(i),
            Err(_) => ValueKind::Float(v as f64),
        }))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<RawKind, E> {
        Ok(RawKind(match i64::try_from(v) {
            Ok(i) => ValueKind::Int(i),
            Err(_) => ValueKind::Float(v as f64),
        }))
    }
    fn visit_u128<E: de::Error>(self, v: u128) -> Result<RawKind, E> {
        Ok(RawKind(match i64::try_from(v) {
            Ok(i) => ValueKind::Int(i),
            Err(_) => ValueKind::Float(v as f64),
        }))
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<RawKind, E> {
        Ok(RawKind(ValueKind::Float(v)))
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<RawKind, E> {
        Ok(RawKind(ValueKind::Str(v.to_string())))
    }
    fn visit_string<E: de::Error>(self, v: String) -> Result<RawKind, E> {
        Ok(RawKind(ValueKind::Str(v)))
    }
    fn visit_bytes<E: de::Error>(self, v: &[u8]) -> Result<RawKind, E> {
        Ok(RawKind(ValueKind::Str(String::from_utf8_lossy(v).into_owned())))
    }
    fn visit_none<E: de::Error>(self) -> Result<RawKind, E> {
        Ok(RawKind(ValueKind::Null))
    }
    fn visit_unit<E: de::Error>(self) -> Result<RawKind, E> {
        Ok(RawKind(ValueKind::Null))
    }
    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<RawKind, D::Error> {
        RawKind::deserialize(d)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawKind, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element::<Spanned<RawKind>>()? {
            items.push(spanned_to_value(item));
        }
        Ok(RawKind(ValueKind::Seq(items)))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RawKind, A::Error> {
        let mut entries = Vec::new();
        while let Some((k, v)) = map.next_entry::<Spanned<RawKind>, Spanned<RawKind>>()? {
            entries.push((spanned_to_value(k), spanned_to_value(v)));
        }
        Ok(RawKind(ValueKind::Map(entries)))
    }
}

/// Read YAML text into a spanned [`Value`], never panicking, with resource limits
/// ([`MAX_FILE_BYTES`], [`MAX_YAML_DEPTH`], [`MAX_YAML_NODES`], alias limits).
///
/// An empty document (or one with only comments) is an error: a tree file needs `main:`.
pub fn parse_yaml(text: &str, file: FileId) -> Result<Value, Issue> {
    let whole = Loc::file_start(file);
    if text.len() > MAX_FILE_BYTES {
        return Err(Issue::new(
            whole,
            format!(
                "file is too large: {} bytes (limit {} bytes)",
                text.len(),
                MAX_FILE_BYTES
            ),
        )
        .help("a behavior tree file is a few kilobytes; is this the right file?"));
    }
    if text.trim().is_empty()
        || text
            .lines()
            .all(|l| l.trim().is_empty() || l.trim_start().starts_with('#'))
    {
        return Err(Issue::new(whole, "the file is empty")
            .label("expected a mapping with a `main:` tree")
            .help("start the file with `main:` followed by the root node, e.g. `main: {sequence: {children: [...]}}`"));
    }
    let budget = serde_saphyr::budget! {
        max_depth: MAX_YAML_DEPTH,
        max_nodes: MAX_YAML_NODES,
        max_events: 4 * MAX_YAML_NODES,
        max_aliases: 1_000,
        max_anchors: 1_000,
        max_documents: 1,
        max_total_scalar_bytes: MAX_FILE_BYTES,
        max_inclusion_depth: 0,
    };
    let options = serde_saphyr::options! {
        budget: budget,
        alias_limits: serde_saphyr::alias_limits! {
            max_total_replayed_events: 4 * MAX_YAML_NODES,
            max_replay_stack_depth: 16,
        },
        with_snippet: false,
        // YAML 1.2 booleans only: `off:`, `on:`, `no:` are names, not booleans.
        strict_booleans: true,
        // `.inf`/`.nan` are read as numbers so that the parameter check can explain the problem.
        non_finite_float_policy: serde_saphyr::NonFiniteFloatPolicy::PassThrough,
    };
    let parsed: Result<Spanned<RawKind>, _> = serde_saphyr::from_str_with_options(text, options);
    match parsed {
        Ok(s) => {
            let mut v = spanned_to_value(s);
            v.set_file(file);
            if v.node_count() > MAX_YAML_NODES {
                return Err(Issue::new(
                    whole,
                    format!("the file expands to more than {MAX_YAML_NODES} YAML nodes"),
                )
                .help("remove YAML aliases that multiply content (`*anchor` inside repeated lists)"));
            }
            Ok(v)
        }
        Err(e) => Err(yaml_error(&e, text, file)),
    }
}

fn yaml_error(e: &serde_saphyr::Error, text: &str, file: FileId) -> Issue {
    let loc = e.location().map_or(Loc::file_start(file), |l| {
        let mut loc = loc_of(&l);
        loc.file = file;
        if loc.line == 0 {
            loc.line = 1;
            loc.col = 1;
        }
        loc
    });
    let raw = e
        .render_with_options(serde_saphyr::render_options! {
            snippets: serde_saphyr::SnippetMode::Off,
        })
        .to_string();
    // The plain rendering ends with " at line X, column Y"; we print the location ourselves.
    let msg = match raw.rfind(" at line ") {
        Some(i) => raw[..i].to_string(),
        None => raw,
    };
    let msg: String = msg
        .lines()
        .next()
        .unwrap_or("invalid YAML")
        .chars()
        .take(300)
        .collect();
    if let Some((message, help)) = plain_message(e, &msg) {
        return Issue::new(loc, message).help(help);
    }
    if let Some(issue) = indentation_issue(text, loc, &msg) {
        return issue;
    }
    let lower = msg.to_lowercase();
    let help = if lower.contains("budget")
        || lower.contains("alias")
        || lower.contains("depth")
        || lower.contains("limit")
    {
        "tree files must stay small and shallow: avoid deep nesting and YAML anchors/aliases that multiply content"
    } else {
        "fix the YAML syntax here (indentation, a missing `:` or an unclosed bracket or quote)"
    };
    Issue::new(loc, format!("invalid YAML: {msg}")).help(help)
}

/// One non-blank, non-comment line of a YAML file.
#[derive(Clone, Copy)]
struct Line<'a> {
    /// 1-based line number.
    no: u32,
    /// Leading spaces.
    indent: usize,
    /// The text after the indentation, without a trailing comment's spaces.
    text: &'a str,
}

impl Line<'_> {
    /// The line opens a block whose content follows on deeper lines (`key:`, `- key:`, `-`).
    fn opens_block(&self) -> bool {
        let t = self.text.split(" #").next().unwrap_or("").trim_end();
        t.ends_with(':') || t == "-" || t.ends_with('|') || t.ends_with('>')
    }
    /// The line is a list item (`- …`).
    fn is_item(&self) -> bool {
        self.text == "-" || self.text.starts_with("- ")
    }
    fn loc(&self, file: FileId) -> Loc {
        Loc {
            file,
            line: self.no,
            col: self.indent as u32 + 1,
            len: self.text.chars().count().max(1) as u32,
        }
    }
}

fn content_lines(text: &str) -> Vec<Line<'_>> {
    text.lines()
        .enumerate()
        .filter_map(|(i, raw)| {
            let text = raw.trim_start_matches(' ');
            let t = text.trim();
            (!t.is_empty() && !t.starts_with('#') && !t.starts_with('\t')).then(|| Line {
                no: u32::try_from(i + 1).unwrap_or(u32::MAX),
                indent: raw.len() - text.len(),
                text: text.trim_end(),
            })
        })
        .collect()
}

/// The parser's indentation errors (`did not find expected key`, `mapping values are not
/// allowed in this context`, …) in our words, pointing at the line whose indentation is wrong:
/// often the line the parser stopped at, sometimes the one before it (the first child of a
/// mapping sets its indentation; a sibling written at the usual indentation after it is where
/// the parser notices). `None` when the lines do not show an indentation mistake.
fn indentation_issue(text: &str, at: Loc, raw: &str) -> Option<Issue> {
    const SYNTAX: [&str; 4] = [
        "did not find expected key",
        "mapping values are not allowed",
        "did not find expected '-' indicator",
        "block sequence entries are not allowed",
    ];
    if !SYNTAX.iter().any(|s| raw.contains(s)) || at.line == 0 {
        return None;
    }
    let file = at.file;
    let lines = content_lines(text);
    let upto: Vec<Line> = lines.iter().copied().filter(|l| l.no <= at.line).collect();
    let (e, before) = upto.split_last()?;
    let p = before.last()?;
    let shown = |l: &Line| -> String { l.text.chars().take(40).collect() };
    // The usual indentation step of the file (2 unless most nested lines say otherwise).
    let step = {
        let mut counts = std::collections::BTreeMap::new();
        for w in lines.windows(2) {
            if w[1].indent > w[0].indent && w[0].opens_block() {
                *counts.entry(w[1].indent - w[0].indent).or_insert(0u32) += 1;
            }
        }
        counts
            .into_iter()
            .max_by_key(|&(d, c)| (c, std::cmp::Reverse(d)))
            .map_or(2, |(d, _)| d)
    };
    // A line at a list's indentation without "- ".
    if !e.is_item()
        && let Some(sib) = before.iter().rev().find(|l| l.indent <= e.indent)
        && sib.indent == e.indent
        && sib.is_item()
    {
        return Some(
            Issue::new(e.loc(file), "a list item needs \"- \"")
                .label(format!(
                    "the items of this list start with `- ` (line {})",
                    sib.no
                ))
                .help(format!("write `- {}`", shown(e))),
        );
    }
    if e.indent > p.indent && !p.opens_block() {
        return Some(
            Issue::new(e.loc(file), "this line is indented deeper than its siblings")
                .label(format!(
                    "{} spaces here, {} on line {} above",
                    e.indent, p.indent, p.no
                ))
                .help(format!(
                    "indent it by {} spaces like line {} (`{}`); if it belongs inside the line above, end that line with `:` and put its value on the lines below",
                    p.indent,
                    p.no,
                    shown(p)
                )),
        );
    }
    if e.indent < p.indent {
        // The open blocks around the line above: each ancestor, from the innermost.
        let mut chain = vec![*p];
        for l in before.iter().rev() {
            if l.indent < chain.last().map_or(0, |c| c.indent) {
                chain.push(*l);
            }
        }
        if chain.iter().any(|c| c.indent == e.indent) {
            return None;
        }
        let sibling = chain.iter().rev().find(|c| c.indent > e.indent)?;
        let parent = chain.iter().find(|c| c.indent < e.indent);
        let first_child = parent.is_some_and(|par| {
            lines
                .iter()
                .find(|l| l.no > par.no)
                .is_some_and(|l| l.no == sibling.no)
        });
        if let Some(par) = parent
            && first_child
            && e.indent == par.indent + step
        {
            // The first child set a deeper indentation than its parent's usual step.
            return Some(
                Issue::new(
                    sibling.loc(file),
                    "this line is indented deeper than its siblings",
                )
                .label(format!(
                    "{} spaces here, {} on line {} (`{}`)",
                    sibling.indent,
                    e.indent,
                    e.no,
                    shown(e)
                ))
                .help(format!(
                    "indent it by {} spaces, like the other entries of line {} (`{}`)",
                    e.indent,
                    par.no,
                    shown(par)
                )),
            );
        }
        let mut help = format!(
            "indent it by {} spaces like line {} (`{}`)",
            sibling.indent,
            sibling.no,
            shown(sibling)
        );
        if let Some(par) = parent {
            help += &format!(", or by {} to end the block of line {}", par.indent, par.no);
        }
        return Some(
            Issue::new(e.loc(file), "this line is indented shallower than its siblings")
                .label(format!(
                    "{} spaces here, {} on line {}",
                    e.indent, sibling.indent, sibling.no
                ))
                .help(help),
        );
    }
    None
}

/// Our own words (message, help) for the parser's limits and duplicate keys, whose own messages
/// name internals (`Nodes { nodes: 100001 }`, "set DuplicateKeyPolicy in Options").
fn plain_message(e: &serde_saphyr::Error, raw: &str) -> Option<(String, &'static str)> {
    use serde_saphyr::budget::BudgetBreach;
    const SHALLOW: &str =
        "tree files must stay small and shallow: nest nodes less deeply, or move parts into subtrees";
    const ALIASES: &str =
        "write the repeated part once as a subtree (`subtrees:`) instead of YAML anchors and aliases";
    let mut inner = e;
    while let serde_saphyr::Error::AliasError { error, .. } | serde_saphyr::Error::WithSnippet { error, .. } =
        inner
    {
        inner = error;
    }
    if let serde_saphyr::Error::DuplicateMappingKey { key, .. } = inner {
        return Some((
            match key {
                Some(k) => format!("`{k}` is given twice in this mapping"),
                None => "a key is given twice in this mapping".to_string(),
            },
            "keep one of them: YAML keys must be unique, and a second one would silently win",
        ));
    }
    if let serde_saphyr::Error::Budget { breach, .. } = inner {
        return Some(match breach {
            BudgetBreach::Depth { .. } => (
                format!("the YAML is nested more than {MAX_YAML_DEPTH} levels deep"),
                SHALLOW,
            ),
            BudgetBreach::Nodes { .. } | BudgetBreach::Events { .. } => (
                format!("the YAML holds more than {MAX_YAML_NODES} values once aliases are expanded"),
                "a tree needs far fewer: write a repeated part once as a subtree (`subtrees:`) instead of copies or YAML aliases",
            ),
            BudgetBreach::Aliases { aliases } => (format!("too many YAML aliases ({aliases})"), ALIASES),
            BudgetBreach::Anchors { anchors } => (format!("too many YAML anchors ({anchors})"), ALIASES),
            BudgetBreach::Documents { .. } => (
                "a tree file holds one YAML document; this is the second (`---`)".to_string(),
                "split the documents into separate files, or remove the `---` line",
            ),
            _ => return None,
        });
    }
    raw.contains("recursion limit").then(|| {
        (
            "the YAML is nested too deeply for the parser (recursion limit)".to_string(),
            SHALLOW,
        )
    })
}

/// Read raw bytes (e.g. a file's content) as UTF-8 tree text; invalid UTF-8 is an error located
/// at the first bad byte.
pub fn decode_utf8(bytes: &[u8], file: FileId) -> Result<&str, Issue> {
    if bytes.len() > MAX_FILE_BYTES {
        return Err(Issue::new(
            Loc::file_start(file),
            format!(
                "file is too large: {} bytes (limit {} bytes)",
                bytes.len(),
                MAX_FILE_BYTES
            ),
        )
        .help("a behavior tree file is a few kilobytes; is this the right file?"));
    }
    std::str::from_utf8(bytes).map_err(|e| {
        let good = &bytes[..e.valid_up_to()];
        let good = std::str::from_utf8(good).unwrap_or("");
        let line = good.matches('\n').count() + 1;
        let col = good.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        Issue::new(
            Loc {
                file,
                line: u32::try_from(line).unwrap_or(u32::MAX),
                col: u32::try_from(col).unwrap_or(u32::MAX),
                len: 1,
            },
            format!(
                "the file is not valid UTF-8 (bad byte at offset {})",
                e.valid_up_to()
            ),
        )
        .help("save the tree file as UTF-8 text; is this a binary file?")
    })
}

/// What `v` is, without its content.
pub fn kind_of(v: &Value) -> &'static str {
    match v.kind {
        ValueKind::Null => "nothing (an empty document)",
        ValueKind::Bool(_) => "a boolean",
        ValueKind::Int(_) | ValueKind::Float(_) => "a number",
        ValueKind::Str(_) => "text",
        ValueKind::Seq(_) => "a list",
        ValueKind::Map(_) => "a mapping",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_point_at_values() {
        let v = parse_yaml("main:\n  seq: [1, two, 3.5]\n", 0).unwrap();
        let main = v.get("main").unwrap();
        assert_eq!((main.loc.line, main.loc.col), (2, 3));
        let seq = main.get("seq").unwrap().as_seq().unwrap();
        assert_eq!(seq[1].kind, ValueKind::Str("two".into()));
        assert_eq!((seq[1].loc.line, seq[1].loc.col, seq[1].loc.len), (2, 12, 3));
        assert_eq!(seq[2].kind, ValueKind::Float(3.5));
    }

    #[test]
    fn syntax_error_is_located() {
        let e = parse_yaml("main:\n  a: [1, 2\n", 0).unwrap_err();
        assert!(e.message.starts_with("invalid YAML"), "{e:?}");
        assert!(e.loc.line >= 2, "{e:?}");
    }

    /// (line, message) of the parse error of `text`.
    fn indentation(text: &str) -> (u32, String) {
        let e = parse_yaml(text, 0).unwrap_err();
        (e.loc.line, e.message)
    }

    #[test]
    fn indentation_mistakes_are_explained_at_the_wrong_line() {
        let deeper = "this line is indented deeper than its siblings";
        let shallower = "this line is indented shallower than its siblings";
        let item = "a list item needs \"- \"";
        let cases = [
            // A second item indented under the first.
            (
                "main:\n  sequence:\n    children:\n      - home: {}\n        - reach: {target: cube}\n",
                5,
                deeper,
            ),
            // An item one space short.
            (
                "main:\n  sequence:\n    children:\n      - home: {}\n     - reach: {target: cube}\n",
                5,
                shallower,
            ),
            // A list item without its dash.
            (
                "main:\n  sequence:\n    children:\n      - home: {}\n      reach: {target: cube}\n",
                5,
                item,
            ),
            // A key one space too deep after a sibling.
            (
                "main:\n  sequence:\n    name: x\n     children:\n      - home: {}\n",
                4,
                deeper,
            ),
            // A key one space short.
            (
                "main:\n  sequence:\n    name: x\n   children:\n      - home: {}\n",
                4,
                shallower,
            ),
            // The first key too deep: the parser stops at its sibling, one line later.
            (
                "main:\n  sequence:\n     name: x\n    children:\n      - home: {}\n",
                3,
                deeper,
            ),
            // A decorator's key too deep.
            (
                "main:\n  retry:\n    attempts: 3\n      child: {home: {}}\n",
                4,
                deeper,
            ),
        ];
        for (text, line, message) in cases {
            assert_eq!(indentation(text), (line, message.to_string()), "{text}");
        }
    }

    #[test]
    fn empty_file_is_an_error() {
        assert!(parse_yaml("", 0).is_err());
        assert!(parse_yaml("# only a comment\n", 0).is_err());
    }

    #[test]
    fn alias_bomb_is_rejected() {
        let mut s = String::from("a: &a [x, x, x, x, x, x, x, x, x, x]\n");
        for i in 1..12 {
            s.push_str(&format!(
                "{}: &{} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n",
                (b'a' + i) as char,
                (b'a' + i) as char,
                p = (b'a' + i - 1) as char
            ));
        }
        assert!(parse_yaml(&s, 0).is_err());
    }

    #[test]
    fn deep_nesting_is_rejected() {
        let s = "[".repeat(100_000);
        assert!(parse_yaml(&s, 0).is_err());
        let mut s = String::new();
        for i in 0..2000 {
            s.push_str(&" ".repeat(i));
            s.push_str("a:\n");
        }
        assert!(parse_yaml(&s, 0).is_err());
    }
}
