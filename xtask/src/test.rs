//! `cargo xtask test`: every test of the project — `cargo test --workspace`,
//! then the Python package's: the `hydrocyl` wheel built by maturin
//! (`crates/python`), installed into a virtual environment under the target
//! folder (`py-venv`, with maturin, numpy, pytest, dask and distributed
//! from PyPI), and its pytest suite run against the `hydrocyl` CLI binary.
//! Then the FMU tests with FMPy (`crates/fmu/tests/run_fmpy_tests.sh`).
//! Fails on any failure, including a pytest run that collects no test.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// What the Python half installs into the virtual environment.
const PY_TOOLS: &[&str] = &["maturin>=1.9,<2", "numpy", "pytest", "dask", "distributed"];

/// Options of `cargo xtask test`.
pub struct Options {
    /// Skip `cargo test --workspace`.
    pub python_only: bool,
    /// Skip the Python package.
    pub rust_only: bool,
    /// Build the wheel with the release profile (as a user gets it) instead
    /// of the dev profile that `cargo test` already compiled.
    pub release: bool,
    /// Remove the virtual environment first.
    pub fresh: bool,
    /// Extra pytest arguments.
    pub pytest_args: Vec<String>,
}

/// Runs a command, echoing it; true when it exits 0.
fn run(what: &str, cmd: &mut Command) -> Result<(), String> {
    eprintln!("xtask test: {what}");
    let start = Instant::now();
    let status = cmd
        .status()
        .map_err(|e| format!("{what}: cannot start {:?}: {e}", cmd.get_program()))?;
    eprintln!(
        "xtask test: {what}: {status} after {:.0} s",
        start.elapsed().as_secs_f64()
    );
    if status.success() {
        Ok(())
    } else {
        Err(format!("{what} failed ({status})"))
    }
}

fn cargo() -> Command {
    Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
}

/// The workspace root and its target folder (`cargo metadata`).
fn layout() -> Result<(PathBuf, PathBuf), String> {
    let out = cargo()
        .args(["metadata", "--format-version", "1", "--no-deps"])
        .output()
        .map_err(|e| format!("cargo metadata: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "cargo metadata: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let v: serde_json::Value =
        serde_json::from_slice(&out.stdout).map_err(|e| format!("cargo metadata: {e}"))?;
    let path = |k: &str| {
        v.get(k)
            .and_then(|p| p.as_str())
            .map(PathBuf::from)
            .ok_or_else(|| format!("cargo metadata: no `{k}`"))
    };
    Ok((path("workspace_root")?, path("target_directory")?))
}

/// `python -m pip install --quiet`.
fn pip_install(python: &Path) -> Command {
    let mut c = Command::new(python);
    c.args([
        "-m",
        "pip",
        "install",
        "--quiet",
        "--disable-pip-version-check",
    ]);
    c
}

/// The virtual environment's interpreter, creating the environment (with
/// the tools) when it is missing or `fresh`.
fn venv(target: &Path, fresh: bool) -> Result<PathBuf, String> {
    let dir = target.join("py-venv");
    let python = dir.join("bin").join("python");
    if fresh && dir.exists() {
        std::fs::remove_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    if !python.exists() {
        let host = std::env::var("PYTHON").unwrap_or_else(|_| "python3".into());
        run(
            &format!("{host} -m venv {}", dir.display()),
            Command::new(&host).arg("-m").arg("venv").arg(&dir),
        )?;
    }
    run(
        &format!("pip install {}", PY_TOOLS.join(" ")),
        pip_install(&python).args(PY_TOOLS),
    )?;
    Ok(python)
}

/// The Python half: wheel, install, pytest.
fn python(opts: &Options) -> Result<(), String> {
    let (root, target) = layout()?;
    // The binary the tests compare with: `cargo test --workspace` has just
    // built it; alone, build it (its own feature set may rebuild a little).
    let cli = target.join("debug").join("hydrocyl");
    if opts.python_only || !cli.exists() {
        run(
            "cargo build -p hydrocyl-cli",
            cargo().args(["build", "-p", "hydrocyl-cli"]),
        )?;
    }
    let python = venv(&target, opts.fresh)?;
    let wheels = target.join("wheels");
    if wheels.exists() {
        std::fs::remove_dir_all(&wheels).map_err(|e| format!("{}: {e}", wheels.display()))?;
    }
    let profile = if opts.release { "release" } else { "dev" };
    run(
        &format!("maturin build --profile {profile} (crates/python)"),
        Command::new(&python)
            .args([
                "-m",
                "maturin",
                "build",
                "--profile",
                profile,
                "--manifest-path",
            ])
            .arg(root.join("crates/python/Cargo.toml"))
            .arg("--out")
            .arg(&wheels)
            .arg("--interpreter")
            .arg(&python),
    )?;
    let wheel = std::fs::read_dir(&wheels)
        .map_err(|e| format!("{}: {e}", wheels.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|x| x == "whl"))
        .ok_or_else(|| format!("maturin left no wheel in {}", wheels.display()))?;
    run(
        &format!("pip install {}", wheel.display()),
        pip_install(&python)
            .args(["--force-reinstall", "--no-deps"])
            .arg(&wheel),
    )?;
    let mut pytest = Command::new(&python);
    pytest
        .args(["-m", "pytest", "-p", "no:cacheprovider", "-ra"])
        .arg(root.join("crates/python/tests"))
        .args(&opts.pytest_args)
        .env("HYDROCYL_CLI", &cli)
        .current_dir(&root);
    eprintln!("xtask test: pytest crates/python/tests");
    let status = pytest
        .status()
        .map_err(|e| format!("pytest: cannot start: {e}"))?;
    match status.code() {
        Some(0) => Ok(()),
        // pytest's "no tests collected": a suite that ran nothing fails.
        Some(5) => Err("pytest collected no tests (exit code 5)".into()),
        _ => Err(format!("pytest failed ({status})")),
    }
}

/// Runs `cargo xtask test`; false on any failure.
pub fn run_all(opts: &Options) -> bool {
    let result = (|| {
        if !opts.python_only {
            run(
                "cargo test --workspace",
                cargo().args(["test", "--workspace"]),
            )?;
        }
        if !opts.rust_only {
            python(opts)?;
            // the FMU checked by a real importer (FMPy from PyPI, its own venv)
            run(
                "crates/fmu/tests/run_fmpy_tests.sh",
                Command::new("bash").arg("crates/fmu/tests/run_fmpy_tests.sh"),
            )?;
        }
        Ok::<(), String>(())
    })();
    match result {
        Ok(()) => {
            eprintln!("xtask test: all passed");
            true
        }
        Err(e) => {
            eprintln!("xtask test: {e}");
            false
        }
    }
}
