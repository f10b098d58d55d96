//! Helpers shared by the test binaries; each binary uses a part of them.
#![allow(dead_code)]

pub mod browser;
pub mod cell_run;
pub mod cli;
pub mod commands;
pub mod files;
pub mod flagship;
pub mod logs;
pub mod media;
pub mod oracle;
