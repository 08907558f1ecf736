//! `cargo xtask test`: every test of the project, Rust and Python, from one command on a
//! fresh machine with the Rust toolchain and Python ≥ 3.9:
//!
//! 1. `cargo test --workspace` (extra arguments are passed on);
//! 2. a virtual environment in `target/python` with the pinned test requirements
//!    (`pendulum-py/requirements-test.txt`: maturin, numpy, pytest, hypothesis, mypy);
//! 3. the Python package built into it by maturin (`maturin develop --release`, into the
//!    workspace's one `target/`);
//! 4. pytest over `pendulum-py/tests`, then the type stubs checked against the module
//!    (`mypy.stubtest`).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};

/// What `cargo xtask test` takes.
#[derive(clap::Args, Debug)]
pub struct Options {
    /// Skip the Rust tests (only the Python package and its tests).
    #[arg(long)]
    pub python_only: bool,
    /// Skip the Python package and its tests.
    #[arg(long, conflicts_with = "python_only")]
    pub rust_only: bool,
    /// Passed on to `cargo test --workspace`.
    #[arg(last = true)]
    pub cargo_args: Vec<String>,
}

/// Runs the tests; an error names the step that failed.
pub fn run(options: &Options) -> Result<()> {
    let root = crate::workspace_root();
    if !options.python_only {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        step("cargo test --workspace");
        let mut command = Command::new(cargo);
        command.current_dir(&root).args(["test", "--workspace"]).args(&options.cargo_args);
        check(&mut command, "cargo test --workspace")?;
    }
    if options.rust_only {
        return Ok(());
    }
    let venv = root.join("target").join("python");
    let python = environment(&venv, &root)?;
    step("maturin develop --release (the pendulum package, into target/python)");
    let mut build = Command::new(venv.join("bin").join("maturin"));
    build
        .current_dir(root.join("pendulum-py"))
        .env("VIRTUAL_ENV", &venv)
        .env("CARGO_TARGET_DIR", root.join("target"))
        .args(["develop", "--release", "--quiet"]);
    check(&mut build, "maturin develop")?;
    step("pytest pendulum-py/tests");
    let mut pytest = Command::new(&python);
    pytest.current_dir(root.join("pendulum-py")).args(["-m", "pytest", "tests", "-q"]);
    check(&mut pytest, "pytest")?;
    step("mypy.stubtest pendulum._pendulum (the type stubs against the module)");
    let mut stubtest = Command::new(&python);
    stubtest.current_dir(root.join("pendulum-py")).args(["-m", "mypy.stubtest", "pendulum._pendulum"]);
    check(&mut stubtest, "mypy.stubtest")?;
    Ok(())
}

/// The virtual environment at `venv` with the pinned requirements installed (made on
/// first use; pip does nothing when they are already there); its python.
fn environment(venv: &Path, root: &Path) -> Result<PathBuf> {
    let python = venv.join("bin").join("python");
    if !python.exists() {
        step("python3 -m venv target/python");
        let system = std::env::var("PYTHON").unwrap_or_else(|_| "python3".into());
        check(Command::new(system).args(["-m", "venv"]).arg(venv), "python3 -m venv")?;
    }
    step("pip install -r pendulum-py/requirements-test.txt");
    let requirements = root.join("pendulum-py").join("requirements-test.txt");
    check(
        Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "-r"])
            .arg(requirements),
        "pip install",
    )?;
    Ok(python)
}

fn step(what: &str) {
    eprintln!("\n=== {what}");
}

fn check(command: &mut Command, what: &str) -> Result<()> {
    let status =
        command.status().with_context(|| format!("{what}: cannot start {:?}", command.get_program()))?;
    if !status.success() {
        bail!("{what} failed ({status})");
    }
    Ok(())
}
