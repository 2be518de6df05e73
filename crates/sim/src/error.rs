//! Everything that can go wrong in the simulator, each with the file at fault and the fix.

use std::fmt;
use std::path::PathBuf;

#[derive(Debug, Clone, PartialEq)]
pub enum SimError {
    /// The linked MuJoCo library is not the version the bindings were generated for.
    VersionMismatch {
        found: String,
        expected: &'static str,
    },
    /// A scene file, or the Shadow Hand model it includes, is not on disk.
    MissingAsset { path: PathBuf },
    /// MuJoCo refused the model.
    Load { path: PathBuf, message: String },
    /// The model lacks a joint, body or actuator the scene needs.
    MissingElement {
        path: PathBuf,
        kind: &'static str,
        name: String,
    },
    /// The simulation produced NaN or infinite values, or MuJoCo flagged an unstable state.
    Diverged { time: f64, what: String },
    /// A recorded physics state does not fit the scene it is restored into.
    BadState { message: String },
    /// Offscreen rendering could not start or run.
    Render { message: String },
    /// A picture or video could not be written.
    Write { path: PathBuf, message: String },
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::VersionMismatch { found, expected } => write!(
                f,
                "MuJoCo {found} is linked, but dexcube is built for MuJoCo {expected}; run \
                 scripts/setup to fetch it into third_party/mujoco, then rebuild (cargo clean -p mujoco-rs)"
            ),
            SimError::MissingAsset { path } => write!(
                f,
                "missing model file {}: run scripts/setup (or `make demo`) to fetch the Shadow Hand \
                 model, or set DEXCUBE_ASSETS to the folder holding dexcube's assets",
                path.display()
            ),
            SimError::Load { path, message } => write!(
                f,
                "MuJoCo could not load {}: {message}; if a hand mesh or texture is missing, run \
                 scripts/setup again",
                path.display()
            ),
            SimError::MissingElement { path, kind, name } => write!(
                f,
                "{} has no {kind} named '{name}', which this scene needs; regenerate the scenes \
                 with python3 assets/generate.py",
                path.display()
            ),
            SimError::Diverged { time, what } => write!(
                f,
                "the simulation diverged at t = {time:.3} s ({what}); reset the environment"
            ),
            SimError::BadState { message } => write!(
                f,
                "a recorded physics state does not fit this scene ({message}): it was recorded on \
                 another scene or with another MuJoCo; record it again"
            ),
            SimError::Render { message } => write!(
                f,
                "offscreen rendering failed: {message}; it needs EGL and Mesa's software OpenGL \
                 (Debian/Ubuntu: apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri, which \
                 scripts/setup does when run as root)"
            ),
            SimError::Write { path, message } => {
                write!(f, "could not write {}: {message}", path.display())
            }
        }
    }
}

impl std::error::Error for SimError {}
