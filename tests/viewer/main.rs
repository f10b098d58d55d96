//! The viewer: the websocket hub, the replay page and a real headless Chromium.
//!
//! One test binary (`cargo test --release --test viewer`); one file per subject.

#[path = "../support/mod.rs"]
mod support;

mod bundle;
mod cli_view;
mod monitor;
mod real_browser;
mod replay_ui;
mod websocket;
