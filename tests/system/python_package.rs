//! The Python package, as a new user gets it: a fresh virtual environment, the pinned test
//! requirements (`pip install --require-hashes`), `pip install ./python` (maturin builds the wheel
//! from source), then its linters and type checker, its pytest suite (Gymnasium's `check_env` on
//! every id and action mode, the vector env against single envs bit for bit, …) and the ported
//! reference tutorial, `examples/python/scripted_cube_bowl.py`.
//!
//! The virtual environment lives in `target/python-test/venv` and is rebuilt when
//! `python/requirements-test.txt` changes; maturin builds the extension in the workspace's
//! `target/` (cargo holds no lock on it while tests run), so only the extension crate itself is
//! compiled here. Python is `python3`, or `MACROTREE_PYTHON`. `MACROTREE_SKIP_PYTHON_TESTS=1` skips these tests (never
//! under `CI`).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn skip() -> bool {
    let skip = std::env::var("MACROTREE_SKIP_PYTHON_TESTS").is_ok_and(|v| v == "1");
    assert!(
        !(skip && std::env::var_os("CI").is_some()),
        "MACROTREE_SKIP_PYTHON_TESTS=1 under CI: the Python tests must run"
    );
    if skip {
        eprintln!("skipped: MACROTREE_SKIP_PYTHON_TESTS=1");
    }
    skip
}

/// Runs `cmd`, panicking with its output when it fails.
fn run(cmd: &mut Command, what: &str) -> String {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot start: {e}"));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{what} failed ({}):\n{text}", out.status);
    text
}

struct Venv {
    dir: PathBuf,
}

impl Venv {
    fn bin(&self, name: &str) -> PathBuf {
        self.dir.join("bin").join(name)
    }

    /// A command from the environment, with its `bin/` first on PATH (maturin is found there).
    fn command(&self, name: &str) -> Command {
        let mut cmd = Command::new(self.bin(name));
        let path = std::env::var_os("PATH").unwrap_or_default();
        let mut paths = vec![self.dir.join("bin")];
        paths.extend(std::env::split_paths(&path));
        cmd.env("PATH", std::env::join_paths(paths).expect("PATH"))
            .env("VIRTUAL_ENV", &self.dir)
            .env_remove("PYTHONPATH")
            .current_dir(root());
        cmd
    }
}

/// The virtual environment with the pinned requirements and the package freshly installed.
fn installed() -> &'static Venv {
    static VENV: OnceLock<Venv> = OnceLock::new();
    VENV.get_or_init(|| {
        let base = root().join("target/python-test");
        let dir = base.join("venv");
        let requirements = root().join("python/requirements-test.txt");
        let wanted = std::fs::read(&requirements).expect("python/requirements-test.txt");
        let stamp = dir.join(".requirements");
        if std::fs::read(&stamp).ok().as_deref() != Some(&wanted[..]) {
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&base).expect("target/python-test");
            let python = std::env::var("MACROTREE_PYTHON").unwrap_or_else(|_| "python3".into());
            run(
                Command::new(&python).arg("-m").arg("venv").arg(&dir),
                "python3 -m venv",
            );
            let venv = Venv { dir: dir.clone() };
            run(
                venv.command("python")
                    .args(["-m", "pip", "install", "--quiet", "--require-hashes", "-r"])
                    .arg(&requirements),
                "pip install --require-hashes -r python/requirements-test.txt",
            );
            std::fs::write(&stamp, &wanted).expect("requirements stamp");
        }
        let venv = Venv { dir };
        run(
            venv.command("python")
                .args([
                    "-m",
                    "pip",
                    "install",
                    "--quiet",
                    "--no-deps",
                    "--no-build-isolation",
                ])
                .args(["--force-reinstall", "./python"]),
            "pip install ./python",
        );
        venv
    })
}

#[test]
fn python_code_is_linted_formatted_and_typed() {
    if skip() {
        return;
    }
    let venv = installed();
    let dirs = ["python/macrotree", "python/tests", "examples/python"];
    // One configuration for the package, its tests and the examples.
    let config = ["--config", "python/pyproject.toml"];
    run(
        venv.command("ruff").arg("check").args(config).args(dirs),
        "ruff check",
    );
    run(
        venv.command("ruff")
            .args(["format", "--check"])
            .args(config)
            .args(dirs),
        "ruff format --check",
    );
    run(
        venv.command("mypy")
            .args(["--config-file", "python/pyproject.toml"])
            .args(dirs),
        "mypy --strict",
    );
}

#[test]
fn python_tests_pass() {
    if skip() {
        return;
    }
    let venv = installed();
    let out = run(
        venv.command("python")
            .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "python/tests"]),
        "pytest python/tests",
    );
    eprintln!("{out}");
}

#[test]
fn ported_tutorial_passes_the_references_checks() {
    if skip() {
        return;
    }
    let venv = installed();
    let video = root().join("target/python-test/scripted_cube_bowl.mp4");
    let _ = std::fs::remove_file(&video);
    let out = run(
        venv.command("python")
            .arg("examples/python/scripted_cube_bowl.py")
            .arg("--video")
            .arg(&video),
        "examples/python/scripted_cube_bowl.py",
    );
    eprintln!("{out}");
    assert_eq!(out.matches("checks passed").count(), 5, "five rollouts:\n{out}");
    assert!(
        std::fs::metadata(&video).is_ok_and(|m| m.len() > 1000),
        "no video at {video:?}"
    );
}

/// TorchRL's `check_env_specs` on the single environment (both action modes) and the vector
/// environment, in the Python that `MACROTREE_TORCHRL_PYTHON` names (one with torchrl 0.14.1:
/// torch is too heavy for CI). The package is built as a wheel here and installed there.
#[test]
fn torchrl_check_env_specs_passes() {
    let Ok(python) = std::env::var("MACROTREE_TORCHRL_PYTHON") else {
        eprintln!("skipped: set MACROTREE_TORCHRL_PYTHON to a Python with torchrl 0.14.1");
        return;
    };
    if skip() {
        return;
    }
    let venv = installed();
    let wheels = root().join("target/python-test/wheel");
    let _ = std::fs::remove_dir_all(&wheels);
    run(
        venv.command("python")
            .args([
                "-m",
                "pip",
                "wheel",
                "--quiet",
                "--no-deps",
                "--no-build-isolation",
            ])
            .arg("./python")
            .arg("-w")
            .arg(&wheels),
        "pip wheel ./python",
    );
    let wheel = std::fs::read_dir(&wheels)
        .expect("wheel folder")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|x| x == "whl"))
        .expect("a wheel");
    run(
        Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "--force-reinstall"])
            .arg(&wheel),
        "pip install the wheel into MACROTREE_TORCHRL_PYTHON",
    );
    let out = run(
        Command::new(&python)
            .arg("python/tests/check_torchrl.py")
            .current_dir(root())
            .env_remove("PYTHONPATH"),
        "python/tests/check_torchrl.py",
    );
    eprintln!("{out}");
    assert_eq!(out.matches(": passed").count(), 3, "{out}");
}
