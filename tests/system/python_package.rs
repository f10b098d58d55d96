//! The Python package, as a new user gets it: a fresh virtual environment, the pinned test
//! requirements (`pip install --require-hashes`), `pip install ./python` (maturin builds the wheel
//! from source), then its linters and type checker, its pytest suite (Gymnasium's `check_env` on
//! every id and action mode, the vector env against single envs bit for bit, …) and the ported
//! reference tutorial, `examples/python/scripted_cube_bowl.py`.
//!
//! The virtual environment lives in `target/python-test/venv` and is rebuilt when
//! `python/requirements-test.txt` changes; maturin builds the extension in the workspace's
//! `target/` (cargo holds no lock on it while tests run) with the features of `cargo test` (the
//! workspace manifest says how), so only pyo3 and the extension crate itself are compiled here.
//! Python is `python3`, or `MACROTREE_PYTHON`. `MACROTREE_SKIP_PYTHON_TESTS=1` skips these tests
//! (never under `CI`).

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
                .args(["--force-reinstall", "./python/lerobot_env_macrotree"]),
            "pip install ./python/lerobot_env_macrotree",
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
    let dirs = [
        "python/macrotree",
        "python/tests",
        "examples/python",
        "python/lerobot_env_macrotree",
        "python/generate_stub.py",
    ];
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

/// The committed `_native.pyi` is what `python/generate_stub.py` generates from the extension
/// (maturin reads the signatures PyO3 records in it; the release build is the one `pip install`
/// just made).
#[test]
fn the_committed_stub_is_what_the_extension_generates() {
    if skip() {
        return;
    }
    let venv = installed();
    run(
        venv.command("python")
            .args(["python/generate_stub.py", "--check"]),
        "python/generate_stub.py --check",
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

/// The LeRobot env plugin's tests, without LeRobot: its features read from macrotree's spaces,
/// one step per frame, and `is_success` in `final_info` of Gymnasium's `SyncVectorEnv` and
/// `AsyncVectorEnv` built as `lerobot-eval` builds them.
#[test]
fn lerobot_plugin_tests_pass() {
    if skip() {
        return;
    }
    let venv = installed();
    let out = run(
        venv.command("python").args([
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "python/lerobot_env_macrotree/tests",
        ]),
        "pytest python/lerobot_env_macrotree/tests",
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

/// Wheels of the packages in `folders` (paths from the repository root), built with the test
/// environment's pip into a fresh `target/python-test/<into>`, for another Python to install.
fn wheels(into: &str, folders: &[&str]) -> Vec<PathBuf> {
    let dir = root().join("target/python-test").join(into);
    let _ = std::fs::remove_dir_all(&dir);
    run(
        installed()
            .command("python")
            .args([
                "-m",
                "pip",
                "wheel",
                "--quiet",
                "--no-deps",
                "--no-build-isolation",
            ])
            .args(folders)
            .arg("-w")
            .arg(&dir),
        &format!("pip wheel {}", folders.join(" ")),
    );
    std::fs::read_dir(&dir)
        .expect("wheel folder")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "whl"))
        .collect()
}

/// The Python an optional check runs in, named by the environment variable `var`; `None` (the
/// check is skipped, saying what it needs) when `var` is unset or the Python tests are skipped.
fn optional_python(var: &str, needs: &str) -> Option<String> {
    let Ok(python) = std::env::var(var) else {
        eprintln!("skipped: set {var} to a Python with {needs}");
        return None;
    };
    (!skip()).then_some(python)
}

/// Installs `built` (wheels) into `python` as a user would: their dependencies as pip resolves
/// them beside what is there, with the packages `extra`, then these very wheels over any
/// earlier build of them.
fn install_wheels(python: &str, built: &[PathBuf], extra: &[&str]) {
    run(
        Command::new(python)
            .args(["-m", "pip", "install", "--quiet"])
            .args(extra)
            .args(built),
        &format!("pip install {extra:?} and the wheels into {python}"),
    );
    run(
        Command::new(python)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--force-reinstall",
                "--no-deps",
            ])
            .args(built),
        &format!("pip install --force-reinstall the wheels into {python}"),
    );
}

/// Runs `python ARGS…` from the repository root, without `PYTHONPATH` (the installed packages
/// only); its output.
fn run_python(python: &str, args: &[&std::ffi::OsStr]) -> String {
    run(
        Command::new(python)
            .args(args)
            .current_dir(root())
            .env_remove("PYTHONPATH"),
        &format!("{python} {args:?}"),
    )
}

/// TorchRL's `check_env_specs` on the single environment (both action modes) and the vector
/// environment, in the Python that `MACROTREE_TORCHRL_PYTHON` names (one with torchrl 0.14.1:
/// torch is too heavy for CI). The package is built as a wheel here and installed there.
#[test]
fn torchrl_check_env_specs_passes() {
    let Some(python) = optional_python("MACROTREE_TORCHRL_PYTHON", "torchrl 0.14.1") else {
        return;
    };
    let built = wheels("wheel", &["./python"]);
    assert_eq!(built.len(), 1, "one wheel: {built:?}");
    install_wheels(&python, &built, &[]);
    let out = run_python(&python, &["python/tests/check_torchrl.py".as_ref()]);
    eprintln!("{out}");
    assert_eq!(out.matches(": passed").count(), 3, "{out}");
}

/// `python -m macrotree.bc --trainer torch` in the Python that `MACROTREE_TORCH_PYTHON` names
/// (one with PyTorch: too heavy for CI): the package is built as a wheel here and installed
/// there with its `policy` extra and pytest, and `python/tests/test_bc_torch.py` runs there —
/// the PyTorch trainer fits as the numpy one does, repeats itself with its seed, and exports a
/// model the `policy` leaf runs.
#[test]
fn the_pytorch_trainer_tests_pass() {
    let Some(python) = optional_python("MACROTREE_TORCH_PYTHON", "torch") else {
        return;
    };
    let built = wheels("wheel-torch", &["./python"]);
    assert_eq!(built.len(), 1, "one wheel: {built:?}");
    install_wheels(&python, &built, &["pytest", "onnxruntime==1.32.0"]);
    let args = [
        "-m",
        "pytest",
        "-q",
        "-p",
        "no:cacheprovider",
        "python/tests/test_bc_torch.py",
    ];
    let out = run_python(&python, &args.map(std::ffi::OsStr::new));
    eprintln!("{out}");
    assert!(out.contains("2 passed"), "{out}");
}

/// `lerobot-eval --env.type=macrotree` for real, in the Python that `MACROTREE_LEROBOT_PYTHON`
/// names (one with lerobot 0.6: torch is too heavy for CI). The macrotree wheel is built here and
/// installed there with the plugin; `check_lerobot.py` checks that LeRobot's plugin discovery
/// registers the env type, and that `lerobot-eval` reports every episode of the task's own tree a
/// success when it has the frames to finish, and none when it has not.
#[test]
fn lerobot_eval_reports_the_environments_success() {
    let Some(python) = optional_python("MACROTREE_LEROBOT_PYTHON", "lerobot 0.6") else {
        return;
    };
    let built = wheels("wheel-lerobot", &["./python", "./python/lerobot_env_macrotree"]);
    assert_eq!(built.len(), 2, "two wheels: {built:?}");
    install_wheels(&python, &built, &[]);
    let work = root().join("target/python-test/lerobot-eval");
    let _ = std::fs::remove_dir_all(&work);
    let out = run_python(
        &python,
        &[
            "python/lerobot_env_macrotree/tests/check_lerobot.py".as_ref(),
            work.as_os_str(),
        ],
    );
    eprintln!("{out}");
    assert_eq!(out.matches(": passed").count(), 4, "{out}");
}

/// The summary of `macrotree sweep ARGS --json` (exit code 0, or 1 when a scenario failed).
fn sweep_summary(args: &[&str]) -> serde_json::Value {
    let out = Command::new(env!("CARGO_BIN_EXE_macrotree"))
        .arg("sweep")
        .args(args)
        .arg("--json")
        .current_dir(root())
        .output()
        .expect("macrotree sweep starts");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        matches!(out.status.code(), Some(0 | 1)),
        "macrotree sweep {args:?}: {}\n{stdout}{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let json = stdout
        .lines()
        .find(|l| l.starts_with('{'))
        .expect("a JSON summary");
    serde_json::from_str(json).expect("the summary is JSON")
}

/// The node of `summary` whose path ends with `tail`.
fn node<'a>(summary: &'a serde_json::Value, tail: &str) -> &'a serde_json::Value {
    summary["nodes"]
        .as_array()
        .and_then(|nodes| {
            nodes
                .iter()
                .find(|n| n["path"].as_str().is_some_and(|p| p.ends_with(tail)))
        })
        .unwrap_or_else(|| panic!("no node ending with {tail}"))
}

/// docs/learning.md's loop, small: noisy demonstrations of the flagship, a short behaviour
/// cloning of its pick (twice: the same bytes), the learned trees validated and swept on held-out
/// seeds. A policy trained this little fails most picks; the scripted fallback must catch them.
#[test]
fn the_learning_loop_runs_end_to_end_and_its_model_is_reproducible() {
    if skip() {
        return;
    }
    let venv = installed();
    let dir = root().join("target/python-test/learning");
    let _ = std::fs::remove_dir_all(&dir);
    for sub in ["trees/lib", "trees/policies"] {
        std::fs::create_dir_all(dir.join(sub)).expect("learning folders");
    }
    for tree in [
        "learned_cube_to_bowl.yaml",
        "learned_pick_alone.yaml",
        "lib/learned_pick.yaml",
    ] {
        std::fs::copy(root().join("trees").join(tree), dir.join("trees").join(tree)).expect("copy tree");
    }
    let demos = dir.join("demos");
    let demos_arg = demos.to_str().expect("UTF-8 path");
    sweep_summary(&[
        "trees/cube_to_bowl.yaml",
        "--scenarios",
        "30",
        "--seed",
        "1",
        "--dataset",
        demos_arg,
        "--cameras",
        "none",
        "--noise",
        "0.02,10",
        "--only-success",
    ]);
    let model = dir.join("trees/policies/cube_pick.onnx");
    let again = dir.join("again.onnx");
    for out in [&model, &again] {
        run(
            venv.command("python")
                .args(["-m", "macrotree.bc"])
                .arg(&demos)
                .args([
                    "--leaf",
                    "subtree[pick]",
                    "--state",
                    "joints",
                    "--chunk",
                    "20",
                    "--epochs",
                    "30",
                ])
                .arg("--out")
                .arg(out)
                .env("PYTHONPATH", root().join("third_party/pyarrow"))
                .env("OPENBLAS_NUM_THREADS", "1"),
            "python -m macrotree.bc",
        );
    }
    assert_eq!(
        std::fs::read(&model).expect("model"),
        std::fs::read(&again).expect("model again"),
        "the same dataset, settings and seed give the same model"
    );
    let with_fallback = dir.join("trees/learned_cube_to_bowl.yaml");
    let alone = dir.join("trees/learned_pick_alone.yaml");
    run(
        Command::new(env!("CARGO_BIN_EXE_macrotree"))
            .arg("validate")
            .arg(&with_fallback)
            .arg(&alone),
        "macrotree validate",
    );
    let held_out = ["--scenarios", "6", "--seed", "7", "--jobs", "2"];
    let scripted = sweep_summary(&[&["trees/cube_to_bowl.yaml"][..], &held_out].concat());
    let learned = sweep_summary(&[&[with_fallback.to_str().expect("UTF-8")][..], &held_out].concat());
    let policy = node(&learned, "policy[approach and grasp]");
    let fallback = node(&learned, "subtree[scripted_pick]");
    eprintln!(
        "scripted {} / 6, learned with fallback {} / 6; the policy succeeded {} of {} times, the fallback ran {} times",
        scripted["successes"],
        learned["successes"],
        policy["successes"],
        policy["activations"],
        fallback["activations"]
    );
    assert!(
        policy["activations"].as_u64() >= Some(6),
        "the policy ran in every scenario"
    );
    // Every policy failure handed over to the scripted pick.
    assert_eq!(fallback["activations"], policy["failures"]);
    assert!(
        learned["successes"].as_u64() >= scripted["successes"].as_u64().map(|s| s.saturating_sub(1)),
        "the fallback keeps the scripted rate: {learned}"
    );
    let alone = sweep_summary(&[&[alone.to_str().expect("UTF-8")][..], &held_out].concat());
    assert_eq!(alone["scenarios"], 6);
    assert_eq!(node(&alone, "policy[approach and grasp]")["scenarios_ran"], 6);
}
