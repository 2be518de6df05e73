//! Episode starts recorded where the operator began Stage 1: the physics state once the hand
//! has opened from where the last stage left it and the policy takes over, and the pose the
//! operator asked for. CubeRotEnv can reset from them ([`CubeRotEnv::with_starts`],
//! [`CubeRotEnv::reset_from`]), so that training and `eval-stage` see the states the
//! operator hands Stage 1, not only a cube freshly set down on a flat hand: session 12 found
//! that the second understates how often a policy drops the cube in the operator threefold.
//!
//! [`CubeRotEnv::with_starts`]: crate::CubeRotEnv::with_starts
//! [`CubeRotEnv::reset_from`]: crate::CubeRotEnv::reset_from

use std::sync::Arc;

/// One recorded start of Stage 1.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordedStart {
    /// The physics state when the policy took over (`Sim::physics_state`).
    pub state: Vec<f64>,
    /// The pose asked for: position, then quaternion (CubeRotEnv's 7-number pose goal).
    pub pose_goal: Vec<f64>,
    /// Whether the policy that was recorded went on to drop the cube from here.
    pub dropped: bool,
}

/// Recorded starts, and which of a CubeRotEnv's resets begin from them.
#[derive(Clone, Debug)]
pub struct StartMix {
    pub starts: Arc<[RecordedStart]>,
    pub pick: StartPick,
}

/// How a reset picks a recorded start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StartPick {
    /// Training: with this probability a reset begins from a start drawn uniformly, and
    /// otherwise from the usual fresh placement.
    Share(f64),
    /// Evaluation: a reset with seed k begins from start k (modulo their number), so that
    /// episodes 0 to n - 1 visit each start once.
    Numbered,
}
