//! Source locations and user-facing diagnostics.
//!
//! Every problem found in a tree file becomes a [`Diagnostic`] that carries the file, the
//! 1-based line and column (in characters), what was expected and what to do about it. Its
//! [`Display`](std::fmt::Display) looks like rustc's:
//!
//! ```text
//! error: unknown field `targt` in `reach`
//!  --> trees/pick.yaml:7:20
//!   |
//! 7 |           - reach: {targt: cube}
//!   |                     ^^^^^ expected one of `target`, `offset`, `yaw`, `path`, `speed`, `timeout`, `name`
//!   = help: did you mean `target`?
//! ```

use std::fmt;
use std::sync::Arc;

/// Index of a source file in a [`Sources`] table.
pub type FileId = u32;

/// A position in a source file: 1-based line and column (counted in characters, not bytes) and
/// the length in characters of the thing pointed at (at least 1 when rendered).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct Loc {
    /// Which file ([`Sources`] index).
    pub file: FileId,
    /// 1-based line; 0 means "unknown".
    pub line: u32,
    /// 1-based column in characters; 0 means "unknown".
    pub col: u32,
    /// Length in characters of the spanned text (0 = unknown).
    pub len: u32,
}

impl Loc {
    /// A location in `file` whose line and column are unknown (e.g. the file as a whole).
    pub fn file_start(file: FileId) -> Self {
        Self {
            file,
            line: 1,
            col: 1,
            len: 0,
        }
    }
}

/// One problem in a tree file, located and explained.
///
/// Diagnostics are plain data so that tests can assert on `line`/`column`, and the CLI can
/// print them with `{}` (rustc-like layout, see the module docs).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    /// File name as given to the loader (e.g. `trees/pick.yaml`).
    pub file: String,
    /// 1-based line (0 if unknown).
    pub line: u32,
    /// 1-based column in characters (0 if unknown).
    pub column: u32,
    /// What is wrong, one line, lower case (e.g. "unknown node kind `sequnce`").
    pub message: String,
    /// Short text under the caret: what was expected there.
    pub label: Option<String>,
    /// What to do about it (e.g. "did you mean `sequence`?").
    pub help: Option<String>,
    /// Extra context (e.g. where a `$param` value came from).
    pub note: Option<String>,
    /// The source line the error points into, if known (without the line break); a long line is
    /// cut to a window around the column, with `…` where text was left out.
    pub source_line: Option<String>,
    /// Where the caret starts in `source_line` (1-based, in characters): `column`, unless the
    /// line was cut.
    pub source_column: u32,
    /// Width of the caret underline in characters (at least 1).
    pub width: u32,
    /// A warning (the tree is accepted, but this is probably not what was meant) rather than an
    /// error.
    pub warning: bool,
}

impl Diagnostic {
    /// An error at `file:line:column` whose source line is not at hand (a file read earlier):
    /// no quote, no label, help or note.
    pub fn at(file: impl Into<String>, line: u32, column: u32, message: impl Into<String>) -> Self {
        Self {
            file: file.into(),
            line,
            column,
            message: sanitize(&message.into()),
            label: None,
            help: None,
            note: None,
            source_line: None,
            source_column: column,
            width: 1,
            warning: false,
        }
    }

    /// `file:line:column`, the way editors and terminals make it clickable.
    pub fn location(&self) -> String {
        format!("{}:{}:{}", self.file, self.line, self.column)
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let severity = if self.warning { "warning" } else { "error" };
        writeln!(f, "{severity}: {}", self.message)?;
        let gutter = self.line.to_string().len();
        let pad = " ".repeat(gutter);
        write!(f, "{pad}--> {}", self.location())?;
        if let Some(src) = &self.source_line {
            // Replace tabs so the caret lines up.
            let shown: String = src.chars().map(|c| if c == '\t' { ' ' } else { c }).collect();
            writeln!(f)?;
            writeln!(f, "{pad} |")?;
            writeln!(f, "{} | {}", self.line, shown.trim_end())?;
            let before = " ".repeat(self.source_column.saturating_sub(1) as usize);
            let carets = "^".repeat(self.width.max(1) as usize);
            write!(f, "{pad} | {before}{carets}")?;
            if let Some(label) = &self.label {
                write!(f, " {label}")?;
            }
        } else if let Some(label) = &self.label {
            writeln!(f)?;
            write!(f, "{pad} = {label}")?;
        }
        if let Some(note) = &self.note {
            writeln!(f)?;
            write!(f, "{pad} = note: {note}")?;
        }
        if let Some(help) = &self.help {
            writeln!(f)?;
            write!(f, "{pad} = help: {help}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostic {}

/// A problem found while reading a tree, before it is turned into a [`Diagnostic`] (which needs
/// the file name and text from [`Sources`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Issue {
    /// Where.
    pub loc: Loc,
    /// What is wrong.
    pub message: String,
    /// What was expected at that spot.
    pub label: Option<String>,
    /// What to do.
    pub help: Option<String>,
    /// Extra context.
    pub note: Option<String>,
}

impl Issue {
    /// A new issue at `loc` with `message`.
    pub fn new(loc: Loc, message: impl Into<String>) -> Self {
        Self {
            loc,
            message: message.into(),
            label: None,
            help: None,
            note: None,
        }
    }

    /// Set the caret label (what was expected).
    #[must_use]
    pub fn label(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }

    /// Set the help text (what to do).
    #[must_use]
    pub fn help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// Set the help text if there is one.
    #[must_use]
    pub fn maybe_help(mut self, help: Option<String>) -> Self {
        if help.is_some() {
            self.help = help;
        }
        self
    }

    /// Set the note.
    #[must_use]
    pub fn note(mut self, note: impl Into<String>) -> Self {
        self.note = Some(note.into());
        self
    }
}

/// Characters of a source line shown under a diagnostic.
const SHOWN_CHARS: usize = 160;
/// Characters shown before the column when a long line is cut.
const SHOWN_BEFORE: usize = 60;

/// The part of `line` shown for a diagnostic at 1-based column `col`, and the caret's column in
/// it: the whole line when short; otherwise a window that keeps the column in view, with `…` for
/// what was left out (a 1 MB one-line file must not print 1 MB).
fn source_window(line: &str, col: u32) -> (String, u32) {
    let chars: Vec<char> = line.chars().collect();
    let at = (col.max(1) - 1) as usize;
    let start = if at < SHOWN_CHARS - 20 {
        0
    } else {
        at - SHOWN_BEFORE
    };
    let start = start.min(chars.len());
    let end = (start + SHOWN_CHARS).min(chars.len());
    let mut shown = String::new();
    if start > 0 {
        shown.push('…');
    }
    shown.extend(&chars[start..end]);
    if end < chars.len() {
        shown.push('…');
    }
    let column = col.max(1) - start as u32 + u32::from(start > 0);
    (sanitize(&shown), column)
}

/// Replace control characters (except tabs) so that a diagnostic never garbles a terminal, and
/// cut the text to [`MAX_FIELD_CHARS`].
fn sanitize(s: &str) -> String {
    cut_text(s, MAX_FIELD_CHARS)
        .chars()
        .map(|c| {
            if c.is_control() && c != '\t' {
                '\u{FFFD}'
            } else {
                c
            }
        })
        .collect()
}

/// One loaded source file.
#[derive(Clone, Debug)]
pub struct SourceFile {
    /// Display name (path as given, or a test name).
    pub name: String,
    /// Full text (may be empty when the file could not be read, and is when withheld).
    pub text: Arc<str>,
    /// Nothing of the file may be shown ([`Sources::withhold`]).
    pub withheld: bool,
}

/// The help of every diagnostic in a withheld file, in place of whatever the issue said (a
/// parser's label or help may quote the file's text).
const WITHHELD_HELP: &str =
    "nothing of this file is shown: it is not the kind of file expected here, or not named `.yaml`";

/// The table of source files a tree was read from, for turning [`Issue`]s into
/// [`Diagnostic`]s.
#[derive(Clone, Debug, Default)]
pub struct Sources {
    files: Vec<SourceFile>,
}

impl Sources {
    /// An empty table.
    pub fn new() -> Self {
        Self::default()
    }

    /// Register a file and get its id.
    pub fn add(&mut self, name: impl Into<String>, text: impl Into<Arc<str>>) -> FileId {
        self.files.push(SourceFile {
            name: name.into(),
            text: text.into(),
            withheld: false,
        });
        u32::try_from(self.files.len() - 1).unwrap_or(u32::MAX)
    }

    /// Register a file read from disk at `path`: like [`add`](Self::add), except that a file
    /// whose name does not end in `.yaml` or `.yml`, or whose text holds a NUL (which no YAML
    /// file does), is [withheld](Self::withhold) — a credentials file or `/proc/self/environ`
    /// named by mistake is located, never quoted.
    pub fn add_file(&mut self, path: &std::path::Path, text: impl Into<Arc<str>>) -> FileId {
        let text: Arc<str> = text.into();
        let binary = text.contains('\0');
        let id = self.add(path.display().to_string(), text);
        let yaml = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"));
        if binary || !yaml {
            self.withhold(id);
        }
        id
    }

    /// Never quote a line of file `id` in a diagnostic again (it is not the kind of file that
    /// was expected, so its text may be anything); its diagnostics keep `file:line:column`.
    pub fn withhold(&mut self, id: FileId) {
        if let Some(f) = self.files.get_mut(id as usize) {
            f.text = Arc::from("");
            f.withheld = true;
        }
    }

    /// The file with id `id`.
    pub fn get(&self, id: FileId) -> Option<&SourceFile> {
        self.files.get(id as usize)
    }

    /// Number of files.
    pub fn len(&self) -> usize {
        self.files.len()
    }

    /// True if no file was registered.
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    /// Display name of file `id` (or `<unknown>`).
    pub fn name(&self, id: FileId) -> &str {
        self.get(id).map_or("<unknown>", |f| f.name.as_str())
    }

    /// Render `loc` as `file:line:col`.
    pub fn describe(&self, loc: Loc) -> String {
        format!("{}:{}:{}", self.name(loc.file), loc.line, loc.col)
    }

    /// Turn an issue into a self-contained diagnostic.
    pub fn diagnostic(&self, issue: &Issue) -> Diagnostic {
        let file = self.get(issue.loc.file);
        let withheld = file.is_some_and(|f| f.withheld);
        let window = file.and_then(|f| {
            if issue.loc.line == 0 {
                return None;
            }
            f.text
                .lines()
                .nth(issue.loc.line as usize - 1)
                .map(|l| source_window(l, issue.loc.col))
        });
        let (source_line, source_column) = match window {
            Some((line, column)) => (Some(line), column),
            None => (None, issue.loc.col),
        };
        let width = match &source_line {
            Some(l) => {
                let avail = (l.chars().count() as u32 + 1).saturating_sub(source_column.max(1));
                issue.loc.len.clamp(1, avail.max(1))
            }
            None => 1,
        };
        Diagnostic {
            file: file.map_or_else(|| "<unknown>".to_string(), |f| f.name.clone()),
            line: issue.loc.line,
            column: issue.loc.col,
            message: sanitize(&issue.message),
            label: issue.label.as_deref().filter(|_| !withheld).map(sanitize),
            help: match withheld {
                true => Some(WITHHELD_HELP.to_string()),
                false => issue.help.as_deref().map(sanitize),
            },
            note: issue.note.as_deref().filter(|_| !withheld).map(sanitize),
            source_line,
            source_column,
            width,
            warning: false,
        }
    }

    /// Turn warnings into diagnostics (printed `warning:`), sorted and without duplicates.
    pub fn warnings(&self, issues: &[Issue]) -> Vec<Diagnostic> {
        let mut out = self.diagnostics(issues);
        for d in &mut out {
            d.warning = true;
        }
        out
    }

    /// Turn many issues into diagnostics, sorted by file, line and column, without duplicates.
    pub fn diagnostics(&self, issues: &[Issue]) -> Vec<Diagnostic> {
        let mut out: Vec<Diagnostic> = Vec::with_capacity(issues.len());
        let mut sorted: Vec<&Issue> = issues.iter().collect();
        sorted.sort_by_key(|i| (i.loc.file, i.loc.line, i.loc.col));
        for issue in sorted {
            let d = self.diagnostic(issue);
            if !out.contains(&d) {
                out.push(d);
            }
        }
        out
    }
}

/// Most characters of one field of a diagnostic (its message, label, help or note): input
/// quoted in it (a 60 KB object name, a 1 MB layout name) is cut to fit.
pub const MAX_FIELD_CHARS: usize = 1000;

/// `s` when it has at most `max` characters; otherwise its start and its end around a marker
/// saying how many characters were left out, `max` characters or fewer in all (a message never
/// grows with hostile input).
pub fn cut_text(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        return s.to_string();
    }
    let marker = format!(" … ({} characters left out) … ", n - max);
    let keep = max.saturating_sub(marker.chars().count());
    let head = keep * 3 / 4;
    let tail = keep - head;
    let start: String = s.chars().take(head).collect();
    let end: String = s.chars().skip(n - tail).collect();
    format!("{start}{marker}{end}")
}

/// A number as a message shows it: as given up to 12 characters, else in scientific notation
/// with 4 significant digits (a hostile 1e300 or 1e-300 is not printed as 301 digits).
pub fn short_number(x: f64) -> String {
    let plain = format!("{x}");
    if plain.chars().count() <= 12 {
        plain
    } else {
        format!("{x:.3e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cut_text_bounds_hostile_input_and_says_how_much_it_left_out() {
        assert_eq!(cut_text("short", 10), "short");
        let long = format!("unknown object `{}`", "a".repeat(60_000));
        let cut = cut_text(&long, MAX_FIELD_CHARS);
        assert!(cut.chars().count() <= MAX_FIELD_CHARS, "{}", cut.len());
        assert!(
            cut.starts_with("unknown object `aaa") && cut.ends_with("aaa`"),
            "{cut}"
        );
        assert!(cut.contains(&format!(
            "({} characters left out)",
            long.chars().count() - MAX_FIELD_CHARS
        )));
        // Characters, not bytes: a multi-byte text is never split inside a character.
        let wide = "é".repeat(5000);
        assert!(cut_text(&wide, 100).chars().count() <= 100);
    }

    #[test]
    fn display_is_rustc_like() {
        let mut s = Sources::new();
        let f = s.add("t.yaml", "main:\n  sequnce: {}\n");
        let d = s.diagnostic(
            &Issue::new(
                Loc {
                    file: f,
                    line: 2,
                    col: 3,
                    len: 7,
                },
                "unknown node kind `sequnce`",
            )
            .label("expected a node kind")
            .help("did you mean `sequence`?"),
        );
        let text = d.to_string();
        assert_eq!(
            text,
            "error: unknown node kind `sequnce`\n --> t.yaml:2:3\n  |\n2 |   sequnce: {}\n  |   ^^^^^^^ expected a node kind\n  = help: did you mean `sequence`?"
        );
    }

    #[test]
    fn a_long_line_is_shown_as_a_window_around_the_column() {
        // Regression: an error at column 300 000 of a one-line file printed 300 KB of spaces.
        let line = format!("x: [{}bad]", "1, ".repeat(100_000));
        let col = line.find("bad").unwrap() as u32 + 1;
        let mut s = Sources::new();
        let f = s.add("t.yaml", line.as_str());
        let loc = Loc {
            file: f,
            line: 1,
            col,
            len: 3,
        };
        let d = s.diagnostic(&Issue::new(loc, "bad value"));
        let shown = d.source_line.as_deref().unwrap();
        assert!(
            shown.starts_with('…') && shown.chars().count() <= SHOWN_CHARS + 2,
            "{shown}"
        );
        // The caret still points at `bad`, and the location keeps the true column.
        let caret_at: String = shown.chars().skip(d.source_column as usize - 1).take(3).collect();
        assert_eq!(caret_at, "bad");
        assert_eq!(d.column, col);
        assert!(d.to_string().len() < 1_000, "{}", d.to_string().len());
    }

    #[test]
    fn a_short_line_is_shown_whole() {
        assert_eq!(source_window("main: {}", 7), ("main: {}".to_string(), 7));
        let long = "a".repeat(500);
        let (shown, column) = source_window(&long, 10);
        assert_eq!(column, 10);
        assert!(shown.ends_with('…') && shown.chars().count() == SHOWN_CHARS + 1);
    }
}
