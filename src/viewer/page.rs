//! Our page around the MeshCat bundle: served live (scripts by URL) or written standalone with
//! everything inlined (replays, `/download`).

use std::path::{Path, PathBuf};

use base64::Engine as _;
use tungstenite::Bytes;

/// Environment variable naming the MeshCat bundle file or the folder holding `main.min.js`.
pub const BUNDLE_ENV: &str = "MACROTREE_MESHCAT";

/// The page shell (assets/viewer/index.html).
pub const PAGE_HTML: &str = include_str!("../../assets/viewer/index.html");
/// Our page script (assets/viewer/viewer.js).
pub const PAGE_JS: &str = include_str!("../../assets/viewer/viewer.js");
/// Our page style (assets/viewer/viewer.css).
pub const PAGE_CSS: &str = include_str!("../../assets/viewer/viewer.css");

/// Where the MeshCat bundle is read from: `$MACROTREE_MESHCAT` (a file, or a folder with
/// `main.min.js`), else `third_party/meshcat/main.min.js` of this source tree.
pub fn bundle_path() -> PathBuf {
    match std::env::var_os(BUNDLE_ENV) {
        Some(p) if !p.is_empty() => {
            let p = PathBuf::from(p);
            if p.is_dir() { p.join("main.min.js") } else { p }
        }
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("third_party/meshcat/main.min.js"),
    }
}

/// Reads the bundle; `Err(path)` when it is missing or unreadable.
pub fn load_bundle() -> Result<Bytes, PathBuf> {
    let path = bundle_path();
    match std::fs::read(&path) {
        Ok(bytes) if !bytes.is_empty() => Ok(Bytes::from(bytes)),
        _ => Err(path),
    }
}

/// The message for a missing bundle.
pub fn bundle_help(path: &Path) -> String {
    format!(
        "the MeshCat viewer bundle {} is missing: run tools/bootstrap to fetch it (or point {BUNDLE_ENV} at a main.min.js)",
        path.display()
    )
}

/// The live page: scripts and style by URL, connects back to the serving host.
pub fn live_html() -> String {
    PAGE_HTML
        .replace("<!--MACROTREE:MODE-->", "live")
        .replace("<!--MACROTREE:STYLE-->", r#"<link rel="stylesheet" href="/viewer.css">"#)
        .replace(
            "<!--MACROTREE:SCRIPTS-->",
            "<script src=\"/main.min.js\"></script>\n<script src=\"/viewer.js\"></script>\n<script>macrotree.live();</script>",
        )
}

/// Makes JavaScript source safe to inline inside a `<script>` element: `</script` (in any
/// case) becomes `<\/script` and `<!--` becomes `<\!--`, so the code can neither end the
/// element early nor switch the HTML parser into its escaped states. Both rewrites keep the
/// meaning of the code inside strings and comments, the only places these sequences occur
/// in our script and the MeshCat bundle (a regular expression with the `u` flag containing
/// them would break).
fn inline_code(js: &str) -> String {
    let mut out = String::with_capacity(js.len());
    let mut rest = js;
    while let Some(i) = rest.find('<') {
        out.push_str(&rest[..i]);
        let tail = &rest[i..];
        let closes_script = tail
            .get(2..8)
            .is_some_and(|w| tail.starts_with("</") && w.eq_ignore_ascii_case("script"));
        if closes_script {
            out.push_str("<\\/");
            rest = &tail[2..];
        } else if tail.starts_with("<!--") {
            out.push_str("<\\!");
            rest = &tail[2..];
        } else {
            out.push('<');
            rest = &tail[1..];
        }
    }
    out.push_str(rest);
    out
}

/// `value` as JSON text that can sit inside a `<script>` element whatever the strings in it
/// hold: `<`, `>` and `&` are written as `\u003c`, `\u003e`, `\u0026`, and the line
/// separators U+2028/U+2029 as `\u2028`/`\u2029`, so no name (node, object, event) can
/// close the element, open a comment or be read as markup. The JSON value is unchanged.
pub fn script_json(value: &serde_json::Value) -> String {
    let json = value.to_string();
    let mut out = String::with_capacity(json.len() + 16);
    for c in json.chars() {
        match c {
            '<' => out.push_str("\\u003c"),
            '>' => out.push_str("\\u003e"),
            '&' => out.push_str("\\u0026"),
            '\u{2028}' => out.push_str("\\u2028"),
            '\u{2029}' => out.push_str("\\u2029"),
            c => out.push(c),
        }
    }
    out
}

/// A self-contained page: bundle, script and style inlined, `commands` (encoded MeshCat
/// messages, carried as base64) fed synchronously in order, then `meta` (JSON, e.g. the tree
/// timeline, escaped by [`script_json`]) handed to the page. Plays offline. No string in
/// `commands` or `meta` can change the page's markup.
pub fn standalone_html(bundle: &[u8], commands: &[Bytes], meta: Option<&serde_json::Value>) -> String {
    let engine = base64::engine::general_purpose::STANDARD;
    let payload: usize = commands.iter().map(|c| c.len() * 4 / 3 + 8).sum();
    let mut data = String::with_capacity(payload + 64);
    data.push_str("[\n");
    for c in commands {
        data.push('"');
        engine.encode_string(c, &mut data);
        data.push_str("\",\n");
    }
    data.push(']');
    let meta = meta.map_or_else(|| "null".to_owned(), script_json);
    let bundle = String::from_utf8_lossy(bundle);
    let mut scripts = String::with_capacity(bundle.len() + data.len() + PAGE_JS.len() + 256);
    scripts.push_str("<script>\n");
    scripts.push_str(&inline_code(&bundle));
    scripts.push_str("\n</script>\n<script>\n");
    scripts.push_str(&inline_code(PAGE_JS));
    scripts.push_str("\n</script>\n<script>\nmacrotree.replay(");
    scripts.push_str(&data);
    scripts.push_str(", ");
    scripts.push_str(&meta);
    scripts.push_str(");\n</script>");
    PAGE_HTML
        .replace("<!--MACROTREE:MODE-->", "replay")
        .replace(
            "<!--MACROTREE:STYLE-->",
            &format!("<style>\n{PAGE_CSS}\n</style>"),
        )
        .replace("<!--MACROTREE:SCRIPTS-->", &scripts)
}
