//! How a program built on the crate ([`crate::App::run_cli`]) presents itself: its name,
//! description and version ([`crate::ProgramInfo`]) in `--help`, usage lines and
//! `--version`.

use clap::{CommandFactory, FromArgMatches};

use super::Cli;
use crate::app::ProgramInfo;

/// Parses the process's arguments with the name, description and version of `info` (on a bad
/// argument, `--help` or `--version`: prints and exits as clap does).
pub(super) fn parse(info: &ProgramInfo) -> Cli {
    let mut cmd = Cli::command();
    if let Some(name) = info.name {
        cmd = cmd.name(name).bin_name(name).display_name(name);
    }
    if let Some(about) = info.about {
        cmd = cmd.about(about).long_about(None);
    }
    if let Some(version) = info.version {
        cmd = cmd.version(version);
    }
    let mut matches = cmd.clone().get_matches();
    Cli::from_arg_matches_mut(&mut matches).unwrap_or_else(|e| e.with_cmd(&cmd).exit())
}
