//! Shared test helpers: a validating GPU context and a check that validation stayed silent.
#![allow(dead_code)]

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

pub mod blender;
pub mod splat_cpu;
pub mod spots;
pub mod synthetic;
