//! Tracing subscriber setup: pretty and colored on a terminal, JSON lines for machines.

use tracing_subscriber::EnvFilter;

/// Log output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum LogFormat {
    /// Human-readable, colored when stderr is a terminal.
    Pretty,
    /// One JSON object per event.
    Json,
}

/// Installs the global subscriber on stderr. `RUST_LOG` wins over `-v`.
pub fn init(verbose: u8, format: LogFormat) {
    let default = match verbose {
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
            .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
            .without_time()
            .with_target(false)
            .try_init(),
        LogFormat::Json => builder.json().flatten_event(true).try_init(),
    };
}
