//! # dexcube-sim
//!
//! MuJoCo 3.17 (through `mujoco-rs`) with the Shadow Dexterous Hand of Gymnasium-Robotics and
//! dexcube's three cubes: a rigid cube (`rot`), a two-layer block (`layer`) and a physical
//! 2x2x2 cube of eight cubelets on ball joints (`cube`). It loads the scenes from `assets/`
//! with clear errors, steps them in 20-substep control steps with blow-up detection, and reads
//! the physical cube's pose, layer angles, alignment and 24 stickers back for the planner, and
//! the hand's grip on the object from the contacts.

pub mod cube;
pub mod error;
pub mod render;
pub mod rotation;
pub mod scene;
pub mod sim;

pub use error::SimError;
pub use scene::{GRIP_PARTS, HAND_ACTUATORS, HAND_JOINTS, Scene, SceneKind, assets_dir};
pub use sim::{PhysicsScales, Pose, SUBSTEPS, Sim};
