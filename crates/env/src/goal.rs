//! What counts as success, as pure functions of an achieved and a desired goal, so that
//! Hindsight Experience Replay can relabel goals through them without an environment. An
//! environment's `step` uses the same functions, so the two always agree. Also how a goal is
//! led on past where it lies ([`GoalLead`]), which a deployed policy may be shown instead.

use std::f64::consts::PI;

use dexcube_sim::cube::ALIGNED_TOLERANCE;
use dexcube_sim::rotation::{self, Quat};
use serde::{Deserialize, Serialize};

use crate::hand_object::relabelled;

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

    /// The goal `desired` led on past where it lies, as `lead` says, for an object whose goal
    /// is now `achieved`. A goal space with no way on shows `desired` as it is.
    fn led(&self, _achieved: &[f64], desired: &[f64], _lead: GoalLead) -> Vec<f64> {
        desired.to_vec()
    }

    /// Where this test reads the object alike in more than one frame (a cube's rotations onto
    /// itself that it cannot tell apart), the one that brings the achieved orientation nearest
    /// `desired`'s: the rotation `g` whose relabelling reads an orientation q as q·g
    /// ([`crate::in_object_frame`] reads an observation so), and `achieved` read in that
    /// frame. None (the default) where the test reads the object in one frame only.
    fn nearest_frame(&self, _achieved: &[f64], _desired: &[f64]) -> Option<(Quat, Vec<f64>)> {
        None
    }
}

/// A goal shown to a policy further on than the one it is judged by: once the angle still to
/// go is under `within` radians, `share` times what is still to go is added to it (for a pose,
/// its position too), as a controller's integral term adds to an error that persists. A
/// policy trained to the paper's threshold is rewarded as much a few degrees short of its
/// goal as on it, and may settle there; shown the goal further on, it goes on. The success
/// test still reads the goal itself. Session 40 in `results/TRAINING.md` measures it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GoalLead {
    pub share: f64,
    pub within: f64,
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

/// CubeRotEnv's goal: position (3) and orientation quaternion (4, w first), and, when the
/// success test also needs the physical cube left in its good state, the cube's misalignment
/// (8), read as [`LayerGoal`] reads it.
#[derive(Clone, Copy, Debug)]
pub struct RotGoal {
    pub mode: RotMode,
    /// Success radius for the position, metres (paper: 0.01; the authors' code used 0.02).
    pub position_threshold: f64,
    /// Success threshold for the orientation, radians (paper: 0.1; the authors' code 0.2).
    pub angle_threshold: f64,
    /// When set, success also needs every cubelet within this many radians of a
    /// quarter-turn position. The paper's test has none.
    pub square_threshold: Option<f64>,
    /// With `square_threshold`, success also needs the cube intact: no layer turned from
    /// where it was when the episode began. The environment, which knows that start, adds a
    /// quarter turn (π/2) to the achieved misalignment once a layer has turned, so the same
    /// last part of the goal carries both and a relabelled goal (HER) is judged alike. A
    /// policy cannot tell from its goal's size whether it was trained so (its actor never
    /// sees the achieved goal).
    pub intact: bool,
    /// With `intact`, a turned layer also ends the episode as an absorbing failure, as a drop
    /// does: once a layer has gone a whole quarter round the cube is square again and the
    /// observations do not show the turn, so the steps after it would look like any others.
    pub turn_ends: bool,
}

/// Length of a pose goal: position 3, quaternion 4.
const POSE_GOAL: usize = 7;

impl RotGoal {
    /// The paper's thresholds, 0.01 m and 0.1 rad.
    pub fn paper(mode: RotMode) -> RotGoal {
        RotGoal {
            mode,
            position_threshold: 0.01,
            angle_threshold: 0.1,
            square_threshold: None,
            intact: false,
            turn_ends: false,
        }
    }

    /// The same test, and the cube left in its good state.
    pub fn left_square(self) -> RotGoal {
        RotGoal {
            square_threshold: Some(ALIGNED_TOLERANCE),
            ..self
        }
    }

    /// The same test, and the cube left in its good state with no layer turned.
    pub fn left_intact(self) -> RotGoal {
        RotGoal {
            intact: true,
            ..self.left_square()
        }
    }

    /// The same test as [`RotGoal::left_intact`], and a turned layer ends the episode.
    pub fn ending_on_turn(self) -> RotGoal {
        RotGoal {
            turn_ends: true,
            ..self.left_intact()
        }
    }

    /// The goal in `mode` a policy with goal vectors of `size` was trained on: 7 is the
    /// paper's, 8 also needs the good state. `None` for any other size.
    pub fn of_size(mode: RotMode, size: usize) -> Option<RotGoal> {
        match size {
            POSE_GOAL => Some(RotGoal::paper(mode)),
            n if n == POSE_GOAL + 1 => Some(RotGoal::paper(mode).left_square()),
            _ => None,
        }
    }

    /// The desired goal for the pose `pose` (position, then quaternion).
    pub fn desired(&self, pose: &[f64]) -> Vec<f64> {
        self.achieved(pose, 0.0)
    }

    /// The achieved goal of the cube at `pose` and `misalignment` radians out of its good
    /// state (0 for the rigid cube).
    pub fn achieved(&self, pose: &[f64], misalignment: f64) -> Vec<f64> {
        with_misalignment(pose, self.square_threshold, misalignment)
    }
}

/// `goal`, with the cube's misalignment appended when the test reads it.
fn with_misalignment(goal: &[f64], square_threshold: Option<f64>, misalignment: f64) -> Vec<f64> {
    let mut out = goal.to_vec();
    if square_threshold.is_some() {
        out.push(misalignment);
    }
    out
}

/// Whether an achieved goal leaves the cube square: its last part, the misalignment, within
/// `square_threshold`. Always, for a test without one.
fn leaves_square(square_threshold: Option<f64>, achieved: &[f64]) -> bool {
    square_threshold.is_none_or(|threshold| achieved.last().is_some_and(|&m| m < threshold))
}

fn quat(goal: &[f64]) -> rotation::Quat {
    [goal[3], goal[4], goal[5], goal[6]]
}

impl Goal for RotGoal {
    fn size(&self) -> usize {
        POSE_GOAL + self.square_threshold.is_some() as usize
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
        position < self.position_threshold
            && angle < self.angle_threshold
            && leaves_square(self.square_threshold, achieved)
    }

    /// The pose led on: its orientation turned on past the target by `share` times the turn
    /// still to go, about that turn's own axis (in axis and pair modes, the turn that brings
    /// the target's up axis up, either way up in pair mode), and its position moved on alike.
    fn led(&self, achieved: &[f64], desired: &[f64], lead: GoalLead) -> Vec<f64> {
        let (a, d) = (quat(achieved), quat(desired));
        let Some(turn) = self.turn_to_go(&a, &d) else {
            return desired.to_vec();
        };
        let (axis, angle) = turn;
        if angle >= lead.within {
            return desired.to_vec();
        }
        let on = rotation::about(axis, lead.share * angle);
        let orientation = match self.mode {
            // The world turn that takes the cube on, before the target.
            RotMode::Paper => rotation::mul(&on, &d),
            // The same turn expressed in the cube's frame, after the target, so that the
            // target's up axis, seen where the cube now holds it, lies further from up.
            RotMode::Axis | RotMode::Pair => rotation::mul(
                &d,
                &rotation::mul(&rotation::mul(&rotation::conj(&a), &on), &a),
            ),
        };
        let mut goal = desired.to_vec();
        goal[3..POSE_GOAL].copy_from_slice(&rotation::normalise(&orientation));
        for k in 0..3 {
            goal[k] += lead.share * (desired[k] - achieved[k]);
        }
        goal
    }

    /// The cube's rotations onto itself that keep the target's up axis where the test reads
    /// it: about that axis in axis mode (4), and the flips too in pair mode (8). The paper's
    /// test reads the whole orientation, so it has none but the identity.
    fn nearest_frame(&self, achieved: &[f64], desired: &[f64]) -> Option<(Quat, Vec<f64>)> {
        let either_way_up = match self.mode {
            RotMode::Paper => return None,
            RotMode::Axis => false,
            RotMode::Pair => true,
        };
        let (a, d) = (quat(achieved), quat(desired));
        let up = rotation::rotate(&rotation::conj(&d), [0.0, 0.0, 1.0]);
        let keeps_up = |g: &&Quat| {
            let along: f64 = (rotation::rotate(g, up).iter().zip(up))
                .map(|(x, y)| x * y)
                .sum();
            if either_way_up {
                along.abs() > 0.99
            } else {
                along > 0.99
            }
        };
        let off = |g: &Quat| rotation::angle_between(&rotation::mul(&a, g), &d);
        // The identity comes first, so a tie keeps the frame the object is read in.
        let g = (rotation::cube_group().iter())
            .filter(keeps_up)
            .copied()
            .min_by(|g, h| off(g).total_cmp(&off(h)))?;
        let mut reached = achieved.to_vec();
        reached[3..POSE_GOAL].copy_from_slice(&relabelled(&a, &g));
        Some((g, reached))
    }
}

impl RotGoal {
    /// The world turn still to go from orientation `a` to the target `d` as this test reads
    /// it, as a unit axis and an angle: turning `a` by the angle about the axis meets the
    /// test exactly. In axis and pair modes it is the turn that brings the cube axis the
    /// target holds up (either way up in pair mode) up. `None` when there is none to speak of.
    fn turn_to_go(&self, a: &rotation::Quat, d: &rotation::Quat) -> Option<([f64; 3], f64)> {
        let (axis, angle) = match self.mode {
            RotMode::Paper => {
                let e = rotation::mul(d, &rotation::conj(a));
                let e = if e[0] < 0.0 { e.map(|x| -x) } else { e };
                let angle = rotation::angle_between(a, d);
                ([e[1], e[2], e[3]], angle)
            }
            RotMode::Axis | RotMode::Pair => {
                let up = rotation::rotate(&rotation::conj(d), [0.0, 0.0, 1.0]);
                let now = rotation::rotate(a, up);
                let target_z = if self.mode == RotMode::Pair {
                    now[2].signum()
                } else {
                    1.0
                };
                let angle = (now[2] * target_z).clamp(-1.0, 1.0).acos();
                // now × target: about it, `now` turns towards the target.
                ([now[1] * target_z, -now[0] * target_z, 0.0], angle)
            }
        };
        let norm = axis.iter().map(|x| x * x).sum::<f64>().sqrt();
        (angle > 1e-9 && norm > 1e-12).then(|| (axis.map(|x| x / norm), angle))
    }
}

/// LayerOpEnv's goal: the angle between the two layers (1), and, when the success test also
/// needs the physical cube left in its good state, the cube's misalignment (2). The desired
/// misalignment is always 0 and the test reads only the achieved one, so that a relabelled
/// goal (HER) judges a transition by the same rule.
#[derive(Clone, Copy, Debug)]
pub struct LayerGoal {
    /// Success threshold, radians (paper: 0.1).
    pub angle_threshold: f64,
    /// When set, success also needs every cubelet within this many radians of a
    /// quarter-turn position (the paper's good state: 0.1). The paper's test has none.
    pub square_threshold: Option<f64>,
}

impl Default for LayerGoal {
    /// The paper's test: the layer angle within 0.1 rad.
    fn default() -> Self {
        LayerGoal {
            angle_threshold: 0.1,
            square_threshold: None,
        }
    }
}

impl LayerGoal {
    /// The paper's angle test, and the cube left in its good state.
    pub fn square() -> LayerGoal {
        LayerGoal {
            square_threshold: Some(ALIGNED_TOLERANCE),
            ..LayerGoal::default()
        }
    }

    /// The goal a policy with goal vectors of `size` was trained on: 1 is the paper's, 2
    /// also needs the good state. `None` for any other size.
    pub fn of_size(size: usize) -> Option<LayerGoal> {
        match size {
            1 => Some(LayerGoal::default()),
            2 => Some(LayerGoal::square()),
            _ => None,
        }
    }

    /// The desired goal for turning the layer to `angle`.
    pub fn desired(&self, angle: f64) -> Vec<f64> {
        self.achieved(angle, 0.0)
    }

    /// The achieved goal of a layer at `angle` with the cube `misalignment` radians out of
    /// its good state (0 for an object with no side layers).
    pub fn achieved(&self, angle: f64, misalignment: f64) -> Vec<f64> {
        with_misalignment(&[angle], self.square_threshold, misalignment)
    }
}

impl Goal for LayerGoal {
    fn size(&self) -> usize {
        1 + self.square_threshold.is_some() as usize
    }

    fn errors(&self, achieved: &[f64], desired: &[f64]) -> (f64, f64) {
        (0.0, (achieved[0] - desired[0]).abs())
    }

    fn is_success(&self, achieved: &[f64], desired: &[f64]) -> bool {
        self.errors(achieved, desired).1 < self.angle_threshold
            && leaves_square(self.square_threshold, achieved)
    }

    /// The layer's goal angle moved on by `share` times the angle still to go.
    fn led(&self, achieved: &[f64], desired: &[f64], lead: GoalLead) -> Vec<f64> {
        let mut goal = desired.to_vec();
        let to_go = desired[0] - achieved[0];
        if to_go.abs() < lead.within {
            goal[0] += lead.share * to_go;
        }
        goal
    }
}

/// Wraps an angle into (-π, π].
pub fn wrap_angle(angle: f64) -> f64 {
    let wrapped = (angle + PI).rem_euclid(2.0 * PI) - PI;
    if wrapped == -PI { PI } else { wrapped }
}
