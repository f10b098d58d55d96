//! How a program built on the crate ([`crate::App::run_cli`]) presents itself: its name,
//! description and version in `--help`, usage lines and `--version`.

use clap::{CommandFactory, FromArgMatches};

use super::Cli;

/// The name, one-line description and version a `macrotree`-like program shows; `None` keeps
/// macrotree's own.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CliInfo {
    /// The program's name (default `macrotree`).
    pub name: Option<&'static str>,
    /// The description at the top of `--help` (default: macrotree's).
    pub about: Option<&'static str>,
    /// The version `--version` prints (default: macrotree's).
    pub version: Option<&'static str>,
}

impl CliInfo {
    /// Parses the process's arguments with this name, description and version (on a bad
    /// argument, `--help` or `--version`: prints and exits as clap does).
    pub(super) fn parse(self) -> Cli {
        let mut cmd = Cli::command();
        if let Some(name) = self.name {
            cmd = cmd.name(name).bin_name(name).display_name(name);
        }
        if let Some(about) = self.about {
            cmd = cmd.about(about).long_about(None);
        }
        if let Some(version) = self.version {
            cmd = cmd.version(version);
        }
        let mut matches = cmd.clone().get_matches();
        Cli::from_arg_matches_mut(&mut matches).unwrap_or_else(|e| e.with_cmd(&cmd).exit())
    }
}
