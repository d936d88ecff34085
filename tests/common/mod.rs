//! Helpers shared by the integration tests.
#![allow(dead_code, reason = "each test binary uses a different subset")]

use grains::cpu::CpuEngine;
use grains::real::Real;
use grains::scene::{self, Scene};
use std::path::{Path, PathBuf};

/// Path of a shipped scene.
pub fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name)
}

/// Loads a shipped scene.
pub fn shipped(name: &str) -> Scene {
    scene::load(&scene_path(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// Parses scene text.
pub fn parse(text: &str) -> Scene {
    scene::parse(Path::new("test.toml"), text).unwrap_or_else(|e| panic!("{e}"))
}

/// A CPU engine for a scene.
pub fn engine<T: Real>(scene: &Scene) -> CpuEngine<T> {
    CpuEngine::new(scene).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs `f` on a pool of `threads` workers.
pub fn with_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool").install(f)
}
