//! Tracing subscriber setup: a compact, colored line per event on a terminal (simulated time,
//! the node, its transition, the reason), or one JSON object per event for machines.

use std::fmt;

use tracing::field::{Field, Visit};
use tracing::{Event, Level, Subscriber};
use tracing_subscriber::EnvFilter;
use tracing_subscriber::fmt::format::Writer;
use tracing_subscriber::fmt::{FmtContext, FormatEvent, FormatFields};
use tracing_subscriber::registry::LookupSpan;

/// Log output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum LogFormat {
    /// Human-readable, colored when stderr is a terminal.
    Pretty,
    /// One JSON object per event, with every field (tick, sim_time, path, kind, from, to, …).
    Json,
}

/// Installs the global subscriber on stderr. `RUST_LOG` wins over `-v`. With `quiet`, the
/// default level is warn (for commands that run many episodes, such as `bench`).
pub fn init(verbose: u8, format: LogFormat, quiet: bool) {
    let default = match verbose {
        0 if quiet => "macrotree=warn",
        0 => "macrotree=info",
        1 => "macrotree=debug",
        _ => "macrotree=trace",
    };
    let filter = EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new(default));
    let builder = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr);
    let _ = match format {
        LogFormat::Pretty => builder
            .event_format(Pretty {
                ansi: std::io::IsTerminal::is_terminal(&std::io::stderr()),
            })
            .try_init(),
        LogFormat::Json => builder.json().flatten_event(true).try_init(),
    };
}

/// Fields that the pretty line shows in its own way (or leaves to `--log-format json`).
const SHOWN_ELSEWHERE: [&str; 7] = ["message", "tick", "sim_time", "path", "kind", "from", "to"];

#[derive(Default)]
struct Fields {
    message: String,
    sim_time: Option<f64>,
    to: Option<String>,
    rest: Vec<(&'static str, String)>,
}

impl Visit for Fields {
    fn record_f64(&mut self, field: &Field, value: f64) {
        if field.name() == "sim_time" {
            self.sim_time = Some(value);
        } else {
            self.rest.push((field.name(), short_float(field.name(), value)));
        }
    }

    fn record_str(&mut self, field: &Field, value: &str) {
        match field.name() {
            "to" => self.to = Some(value.to_string()),
            "message" => self.message = value.to_string(),
            name if SHOWN_ELSEWHERE.contains(&name) => {}
            name => self.rest.push((name, value.to_string())),
        }
    }

    fn record_debug(&mut self, field: &Field, value: &dyn fmt::Debug) {
        match field.name() {
            "message" => self.message = format!("{value:?}"),
            name if SHOWN_ELSEWHERE.contains(&name) => {}
            name => self.rest.push((name, format!("{value:?}"))),
        }
    }
}

/// A float field for people: times (`…_s`, `…time…`) to the millisecond, anything else to four
/// decimals, without trailing zeros (`5.336`, `0.031`, `2`).
fn short_float(name: &str, value: f64) -> String {
    if !value.is_finite() {
        return format!("{value}");
    }
    let decimals = if name.ends_with("_s") || name.contains("time") {
        3
    } else {
        4
    };
    let s = format!("{value:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" { "0".to_string() } else { s }
}

/// `  2.244 s  reach "above cube" running → success  attempt=1`
struct Pretty {
    ansi: bool,
}

impl Pretty {
    fn paint(&self, code: &str, text: &str) -> String {
        if self.ansi {
            format!("\x1b[{code}m{text}\x1b[0m")
        } else {
            text.to_string()
        }
    }
}

impl<S, N> FormatEvent<S, N> for Pretty
where
    S: Subscriber + for<'a> LookupSpan<'a>,
    N: for<'a> FormatFields<'a> + 'static,
{
    fn format_event(&self, _ctx: &FmtContext<'_, S, N>, mut w: Writer<'_>, event: &Event<'_>) -> fmt::Result {
        let mut f = Fields::default();
        event.record(&mut f);
        let level = *event.metadata().level();
        match f.sim_time {
            Some(t) => write!(w, "{} ", self.paint("2", &format!("{t:7.3} s")))?,
            None => write!(w, "{:9} ", "")?,
        }
        if level != Level::INFO {
            let code = match level {
                Level::ERROR => "31;1",
                Level::WARN => "33;1",
                _ => "2",
            };
            write!(w, "{} ", self.paint(code, level.as_str()))?;
        }
        let code = match f.to.as_deref() {
            Some("success") => "32",
            Some("failure") => "31",
            Some("halted") => "33",
            Some("running") => "36",
            _ => "0",
        };
        write!(w, "{}", self.paint(code, &f.message))?;
        for (name, value) in &f.rest {
            write!(w, "  {}={value}", self.paint("2", name))?;
        }
        writeln!(w)
    }
}

#[cfg(test)]
mod tests {
    use super::short_float;

    #[test]
    fn floats_are_printed_to_a_readable_precision() {
        assert_eq!(short_float("sim_time_s", 5.335999999999634), "5.336");
        assert_eq!(short_float("width", 0.031_000_000_4), "0.031");
        assert_eq!(short_float("width", 2.0), "2");
        assert_eq!(short_float("x", -0.000_01), "0");
        assert_eq!(short_float("x", f64::NAN), "NaN");
    }
}
