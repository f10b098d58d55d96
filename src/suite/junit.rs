//! JUnit XML for `macrotree test --junit FILE.xml`: one `<testcase>` per scenario file, with a
//! `<failure>` that lists the expectations that did not hold and the reproduce commands of the
//! failing cases. The shape is the common one CI systems read (Jenkins, GitLab, GitHub
//! actions that publish test reports): `<testsuites><testsuite name tests failures errors
//! skipped time><testcase classname name time>[<failure message type>text</failure>]
//! [<system-out>…</system-out>]</testcase></testsuite></testsuites>`.

use std::fmt::Write as _;

/// One test case: a scenario file's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// The test case's name: the scenario file relative to its suite folder (see
    /// [`crate::suite::names`]).
    pub name: String,
    /// Wall-clock seconds it took (0 in merged reports).
    pub time_s: f64,
    /// `Some((message, text))` when it failed: a one-line message and the details (failed
    /// expectations, reproduce commands).
    pub failure: Option<(String, String)>,
    /// The summary, for `<system-out>`.
    pub out: String,
}

/// Escapes text for XML content and attribute values; characters XML 1.0 cannot carry
/// (control characters other than tab, newline and carriage return) become `?`.
pub fn escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            '\t' | '\n' | '\r' => o.push(c),
            c if (c as u32) < 0x20 || c == '\u{fffe}' || c == '\u{ffff}' => o.push('?'),
            c => o.push(c),
        }
    }
    o
}

/// The JUnit XML document for `cases` (suite name `macrotree`).
pub fn to_xml(cases: &[Case]) -> String {
    let failures = cases.iter().filter(|c| c.failure.is_some()).count();
    let time: f64 = cases.iter().map(|c| c.time_s).sum();
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<testsuites name=\"macrotree\" tests=\"{}\" failures=\"{failures}\" errors=\"0\" time=\"{time:.3}\">",
        cases.len()
    );
    let _ = writeln!(
        x,
        "  <testsuite name=\"macrotree test\" tests=\"{}\" failures=\"{failures}\" errors=\"0\" skipped=\"0\" time=\"{time:.3}\">",
        cases.len()
    );
    for c in cases {
        let _ = write!(
            x,
            "    <testcase classname=\"scenarios\" name=\"{}\" time=\"{:.3}\">",
            escape(&c.name),
            c.time_s
        );
        if let Some((message, text)) = &c.failure {
            let _ = write!(
                x,
                "\n      <failure message=\"{}\" type=\"expectation\">{}</failure>",
                escape(message),
                escape(text)
            );
        }
        if !c.out.is_empty() {
            let _ = write!(x, "\n      <system-out>{}</system-out>", escape(&c.out));
        }
        x.push_str(if c.failure.is_some() || !c.out.is_empty() {
            "\n    </testcase>\n"
        } else {
            "</testcase>\n"
        });
    }
    x.push_str("  </testsuite>\n</testsuites>\n");
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_and_counts() {
        assert_eq!(
            escape("a<b & 'c' \"d\"\u{1}"),
            "a&lt;b &amp; &apos;c&apos; &quot;d&quot;?"
        );
        let xml = to_xml(&[
            Case {
                name: "ok.yaml".into(),
                time_s: 1.0,
                failure: None,
                out: String::new(),
            },
            Case {
                name: "bad.yaml".into(),
                time_s: 2.5,
                failure: Some(("1 expectation failed".into(), "macrotree run x".into())),
                out: "summary".into(),
            },
        ]);
        assert!(xml.contains("tests=\"2\" failures=\"1\""), "{xml}");
        assert!(xml.contains("time=\"3.500\""), "{xml}");
        assert!(xml.contains(
            "<failure message=\"1 expectation failed\" type=\"expectation\">macrotree run x</failure>"
        ));
    }
}
