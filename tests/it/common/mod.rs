//! Shared test helpers: a validating GPU context and a check that validation stayed silent,
//! the built binary, and per-test folders.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::Arc;

use ocular::gpu::{Context, ContextOptions, ValidationLog};

/// A context on the test device (lavapipe in CI: ci/test.sh pins the loader to it) with the
/// validation layer on whenever it is installed.
pub fn gpu() -> Context {
    match Context::new(&ContextOptions::for_tests()) {
        Ok(ctx) => ctx,
        Err(e) => panic!("GPU tests need a Vulkan device (run ci/setup.sh for Mesa lavapipe): {e}"),
    }
}

/// Drops the context and asserts that validation produced no message during its whole life,
/// its destruction included (which is where leaked objects are reported).
pub fn finish(ctx: Context) {
    let log: Arc<ValidationLog> = ctx.validation_log();
    let validating = ctx.is_validating();
    drop(ctx);
    let messages = log.take();
    assert!(
        messages.is_empty(),
        "validation messages:\n{}",
        messages.join("\n")
    );
    if !validating {
        eprintln!("note: the Vulkan validation layer is not installed; validation was not checked");
    }
}

/// The built `ocular` binary, stdin closed (no test types into it); add arguments, then run.
pub fn ocular() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_ocular"));
    c.stdin(Stdio::null());
    c
}

/// `ocular ARGS` run to the end.
pub fn ocular_run(args: &[&str]) -> Output {
    ocular().args(args).output().unwrap()
}

/// `ocular eye measure EYE --pupil-mm PUPIL --wavelength-nm WAVELENGTH EXTRA…` run to the end.
pub fn eye_measure(eye: &str, pupil_mm: &str, wavelength_nm: &str, extra: &[&str]) -> Output {
    ocular()
        .args(["eye", "measure", eye, "--pupil-mm", pupil_mm])
        .args(["--wavelength-nm", wavelength_nm])
        .args(extra)
        .output()
        .unwrap()
}

/// `ocular eye refract EYE --pupil-mm PUPIL EXTRA…` run to the end.
pub fn eye_refract(eye: &str, pupil_mm: &str, extra: &[&str]) -> Output {
    ocular()
        .args(["eye", "refract", eye, "--pupil-mm", pupil_mm])
        .args(extra)
        .output()
        .unwrap()
}

/// A fresh, empty folder for one test: `ocular-it-PID-MODULE-NAME` in the system's temporary
/// folder, MODULE being the calling test's file, so the tests of every module can share one
/// process (`name` need only be unique within a file).
#[track_caller]
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = folder(&format!("-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A kernel cache shared by the tests of the calling file (they plan the same small grids),
/// `ocular-it-PID-MODULE.cache`, kept for the whole run: a test may find another's kernels.
#[track_caller]
pub fn module_cache() -> PathBuf {
    let dir = folder(".cache");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `ocular-it-PID-MODULE` and `suffix`, in the system's temporary folder.
#[track_caller]
fn folder(suffix: &str) -> PathBuf {
    let file = std::panic::Location::caller().file();
    let module = Path::new(file).file_stem().unwrap().to_string_lossy();
    let pid = std::process::id();
    std::env::temp_dir().join(format!("ocular-it-{pid}-{module}{suffix}"))
}

/// Marsaglia's xorshift64 from `state` (not zero): noise that every run repeats.
pub fn xorshift(mut state: u64) -> impl FnMut() -> u64 {
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    }
}

/// A file of tests/data.
pub fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// A path as a command-line argument.
pub fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// The run succeeded; its stdout.
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The run succeeded; its stdout as JSON.
pub fn json_ok(o: &Output) -> serde_json::Value {
    assert!(
        o.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Refused as bad input: exit 2 and one line on stderr naming every word; that line.
pub fn refused(out: &Output, words: &[&str]) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
    for w in words {
        assert!(err.contains(w), "expected {w:?} in {err}");
    }
    err
}

pub mod blender;
pub mod frames;
pub mod pixels;
pub mod scenes;
pub mod splat_cpu;
pub mod spots;
pub mod synthetic;
