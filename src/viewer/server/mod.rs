//! The live server: plain HTTP for the page and a websocket on the same port, on std threads.
//!
//! Threads: one acceptor, one thread per connection (an HTTP request is answered and closed; a
//! websocket connection stays and becomes a client). The simulation thread never touches a
//! socket: it updates the `Hub` (scene tree + per-client outboxes) under one short lock and
//! wakes the clients' threads.
//!
//! Per client, structural commands (objects, properties, deletes) go through a bounded queue;
//! body poses go into a **slot per body** that the next write empties (latest wins), so a slow
//! or stalled browser skips frames instead of growing a backlog. If its queue overflows, it is
//! cleared and the client is re-sent a snapshot of the tree.
//!
//! Who may connect and for how long: requests must name this server in `Host` and websocket
//! upgrades must come from its own pages (`Origin`), see `guard.rs`; every size and wait
//! is bounded by [`ServerLimits`], and a full server evicts an idle connection rather than
//! refusing the user (see `docs/security.md`).

mod acceptor;
mod client;
mod hub;

pub(crate) use acceptor::{Site, spawn_acceptor, wake_acceptor};
pub use hub::ClientStats;
pub(crate) use hub::Hub;
