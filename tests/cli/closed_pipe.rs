//! Output to a closed pipe (`macrotree … | head -0`) ends a command quietly — by SIGPIPE, which
//! shells report as 141, or with the command's own exit code when it wrote nothing to stdout —
//! never with a panic on the failed write (exit 101).

use std::os::unix::process::ExitStatusExt;
use std::process::{Command, Stdio};

use crate::support::cli::BIN;

const TREE: &str = "trees/cube_to_bowl.yaml";

/// Runs `macrotree ARGS…` with its stdout a pipe whose reading end is closed at once.
fn with_closed_stdout(args: &[&str]) -> (std::process::ExitStatus, String) {
    let mut child = Command::new(BIN)
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env_remove("RUST_LOG")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts the binary");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("waits for the binary");
    (out.status, String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn a_closed_stdout_ends_each_command_quietly_not_in_a_panic() {
    let free = "main/**=success";
    let commands: [&[&str]; 5] = [
        &["nodes"],
        &["validate", TREE],
        &["schema"],
        &["run", TREE, "--substitute", free],
        &["sweep", TREE, "--scenarios", "4", "--substitute", free],
    ];
    for args in commands {
        let (status, stderr) = with_closed_stdout(args);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(
            status.signal() == Some(libc::SIGPIPE) || matches!(status.code(), Some(0 | 1)),
            "{args:?}: {status:?}, {stderr}"
        );
    }
}
