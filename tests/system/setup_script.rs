//! `tools/setup`, the set-up half of the README's test command (`tools/setup && cargo test
//! --release`): on a machine state without the system packages the tests need, it installs them
//! (as root, with apt-get) or stops before anything is built with the exact command to run.
//!
//! The machine state without the packages is a real, empty dpkg database (`DPKG_ADMINDIR`, which
//! `dpkg-query` reads); the install path itself runs on a clean CI machine (`.ci/run` calls the
//! README's test command) — see README "Quick start" for a recorded run.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const PACKAGES: &str = "chromium libegl1 libegl-mesa0 libgl1-mesa-dri";

/// An empty dpkg database: no package is installed.
fn empty_dpkg_db(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("macrotree-test-dpkg-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for sub in ["info", "updates"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    std::fs::write(dir.join("status"), "").unwrap();
    // Readable by `nobody` too.
    use std::os::unix::fs::PermissionsExt as _;
    for p in [dir.clone(), dir.join("info"), dir.join("updates")] {
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    dir
}

fn setup(args: &[&str], dpkg_db: Option<&Path>, as_nobody: bool) -> Output {
    let mut c = if as_nobody {
        // `nobody` may not be able to enter the checkout (e.g. under /root): run a copy of the
        // script from a world-readable folder (it stops before it would need the checkout).
        let dir = std::env::temp_dir().join(format!("macrotree-test-setup-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("tools")).unwrap();
        let copy = dir.join("tools/setup");
        std::fs::copy(Path::new(ROOT).join("tools/setup"), &copy).unwrap();
        use std::os::unix::fs::PermissionsExt as _;
        for p in [dir.clone(), dir.join("tools"), copy.clone()] {
            std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
        }
        let mut c = Command::new("setpriv");
        c.args(["--reuid=65534", "--regid=65534", "--clear-groups"])
            .arg(&copy)
            .current_dir(&dir);
        c
    } else {
        let mut c = Command::new(Path::new(ROOT).join("tools/setup"));
        c.current_dir(ROOT);
        c
    };
    c.args(args).env_remove("MACROTREE_SKIP_BROWSER_TESTS");
    if let Some(db) = dpkg_db {
        c.env("DPKG_ADMINDIR", db);
    }
    c.output().expect("runs tools/setup")
}

fn has_dpkg() -> bool {
    Command::new("dpkg-query")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
fn the_test_command_without_chromium_stops_before_building_and_names_the_install() {
    assert!(has_dpkg(), "these checks need a Debian machine (dpkg-query)");
    let db = empty_dpkg_db("check");
    let out = setup(&["--check"], Some(&db), false);
    let err = String::from_utf8_lossy(&out.stderr);
    // Stops (exit 1, so `&& cargo test` never builds), naming every missing package and the
    // exact command.
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("missing system package(s): {PACKAGES}")),
        "{err}"
    );
    assert!(
        err.contains(&format!(
            "sudo sh -c 'apt-get update && apt-get install -y {PACKAGES}'"
        )),
        "{err}"
    );
    assert!(err.contains("nothing was built"), "{err}");

    // Without root it cannot install, so it stops the same way (also without --check). As root,
    // the script runs as `nobody`; a user with password-less sudo would install, so not there.
    let is_root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.starts_with(b"0\n"));
    let sudo = || {
        Command::new("sudo")
            .args(["-n", "true"])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if is_root || !sudo() {
        let out = setup(&[], Some(&db), is_root);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains("this is not root (nor password-less sudo)"), "{err}");
        assert!(err.contains("apt-get install -y chromium"), "{err}");
    }

    // The browser tests skipped on purpose: Chromium is not asked for.
    let out = Command::new(Path::new(ROOT).join("tools/setup"))
        .arg("--check")
        .env("DPKG_ADMINDIR", &db)
        .env("MACROTREE_SKIP_BROWSER_TESTS", "1")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("missing system package(s): libegl1 libegl-mesa0 libgl1-mesa-dri."),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&db);
}

#[test]
fn setup_with_every_package_installed_goes_on_to_the_bootstrap() {
    // On this machine the packages are installed (by tools/setup itself before `cargo test`, as
    // the README's command and CI run it): the check passes and the bootstrap (already done)
    // returns at once.
    let out = setup(&["--check"], None, false);
    assert_eq!(
        out.status.code(),
        Some(0),
        "run `tools/setup` first: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = setup(&["--bogus"], None, false);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn ci_runs_exactly_the_readme_test_command_and_it_sets_up_first() {
    let readme = std::fs::read_to_string(Path::new(ROOT).join("README.md")).unwrap();
    let ci = std::fs::read_to_string(Path::new(ROOT).join(".ci/run")).unwrap();
    let command = readme
        .lines()
        .find(|l| l.ends_with("cargo test --release"))
        .expect("the README's test command");
    assert_eq!(command, "tools/setup && cargo test --release");
    assert!(
        ci.lines().any(|l| l == command),
        ".ci/run does not run the README's test command `{command}`"
    );
    // What the README says it installs is what the script installs.
    let script = std::fs::read_to_string(Path::new(ROOT).join("tools/setup")).unwrap();
    for p in PACKAGES.split(' ') {
        assert!(readme.contains(p) && script.contains(p), "{p}");
    }
}
