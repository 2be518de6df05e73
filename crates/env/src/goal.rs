//! What counts as success, as pure functions of an achieved and a desired goal, so that
//! Hindsight Experience Replay can relabel goals through them without an environment. An
//! environment's `step` uses the same functions, so the two always agree.

use std::f64::consts::PI;

use dexcube_sim::rotation;

/// A goal space: its size, the success test, and the errors `info` reports.
pub trait Goal: Send + Sync {
    /// Length of a goal vector.
    fn size(&self) -> usize;

    /// Position error (metres) and angle error (radians) between two goals.
    fn errors(&self, achieved: &[f64], desired: &[f64]) -> (f64, f64);

    fn is_success(&self, achieved: &[f64], desired: &[f64]) -> bool;

    /// The paper's sparse reward: 0 on success, -1 otherwise.
    fn compute_reward(&self, achieved: &[f64], desired: &[f64]) -> f64 {
        if self.is_success(achieved, desired) {
            0.0
        } else {
            -1.0
        }
    }
}

/// How CubeRotEnv judges orientation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RotMode {
    /// The paper's test: the whole orientation within the angle threshold.
    Paper,
    /// Only the axis that should point up: the rotation about the vertical is free. This is
    /// all a following layer turn needs.
    Axis,
    /// The target face or the opposite face up, rotation about the vertical free: either way
    /// the move's layer pair lies top and bottom, and a U' of the top layer then makes the
    /// same move (X' and its opposite face's turn, each seen from its own side, are one move
    /// up to a whole-cube turn). The paper's own reason for three poses, not six, taken one
    /// step on: no pose is more than 90° from an accepted one.
    Pair,
}

/// CubeRotEnv's goal: position (3) and orientation quaternion (4, w first).
#[derive(Clone, Copy, Debug)]
pub struct RotGoal {
    pub mode: RotMode,
    /// Success radius for the position, metres (paper: 0.01; the authors' code used 0.02).
    pub position_threshold: f64,
    /// Success threshold for the orientation, radians (paper: 0.1; the authors' code 0.2).
    pub angle_threshold: f64,
}

impl RotGoal {
    /// The paper's thresholds, 0.01 m and 0.1 rad.
    pub fn paper(mode: RotMode) -> RotGoal {
        RotGoal {
            mode,
            position_threshold: 0.01,
            angle_threshold: 0.1,
        }
    }
}

fn quat(goal: &[f64]) -> rotation::Quat {
    [goal[3], goal[4], goal[5], goal[6]]
}

impl Goal for RotGoal {
    fn size(&self) -> usize {
        7
    }

    fn errors(&self, achieved: &[f64], desired: &[f64]) -> (f64, f64) {
        let position = (0..3)
            .map(|k| (achieved[k] - desired[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let (a, d) = (quat(achieved), quat(desired));
        let angle = match self.mode {
            // 2·arccos(|Re(q'·conj(q))|): the angle of the rotation between the two.
            RotMode::Paper => rotation::angle_between(&a, &d),
            // The cube axis the target holds up, and where the achieved pose points it.
            RotMode::Axis | RotMode::Pair => {
                let up = rotation::rotate(&rotation::conj(&d), [0.0, 0.0, 1.0]);
                let now = rotation::rotate(&a, up)[2];
                let cos = if self.mode == RotMode::Pair {
                    now.abs()
                } else {
                    now
                };
                cos.clamp(-1.0, 1.0).acos()
            }
        };
        (position, angle)
    }

    fn is_success(&self, achieved: &[f64], desired: &[f64]) -> bool {
        let (position, angle) = self.errors(achieved, desired);
        position < self.position_threshold && angle < self.angle_threshold
    }
}

/// LayerOpEnv's goal: the angle between the two layers (1).
#[derive(Clone, Copy, Debug)]
pub struct LayerGoal {
    /// Success threshold, radians (paper: 0.1).
    pub angle_threshold: f64,
}

impl Default for LayerGoal {
    fn default() -> Self {
        LayerGoal {
            angle_threshold: 0.1,
        }
    }
}

impl Goal for LayerGoal {
    fn size(&self) -> usize {
        1
    }

    fn errors(&self, achieved: &[f64], desired: &[f64]) -> (f64, f64) {
        (0.0, (achieved[0] - desired[0]).abs())
    }

    fn is_success(&self, achieved: &[f64], desired: &[f64]) -> bool {
        self.errors(achieved, desired).1 < self.angle_threshold
    }
}

/// Wraps an angle into (-π, π].
pub fn wrap_angle(angle: f64) -> f64 {
    let wrapped = (angle + PI).rem_euclid(2.0 * PI) - PI;
    if wrapped == -PI { PI } else { wrapped }
}
