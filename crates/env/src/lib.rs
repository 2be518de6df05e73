//! # dexcube-env
//!
//! The paper's two training environments in Gymnasium-Robotics' goal-env shape: an observation
//! in three parts (`observation`, `achieved_goal`, `desired_goal`), a sparse reward of 0 on
//! success and -1 otherwise computed by pure functions of the goals (so Hindsight Experience
//! Replay can relabel), and `terminated` / `truncated` as in Gymnasium.
//!
//! - [`CubeRotEnv`] (Stage 1): re-pose a rigid 5 cm cube (or the physical 2x2x2 cube) on the
//!   palm; observation 61, goal 7.
//! - [`LayerOpEnv`] (Stage 2): turn one layer of the physical 2x2x2 cube (or of a two-layer
//!   block); observation 62, goal 1.
//!
//! On the physical cube either goal can gain one part, the cube's misalignment, for a success
//! test that also needs the cube left in its good state ([`RotGoal::left_square`],
//! [`LayerGoal::square`]).
//! - [`RecordedStart`]: where the operator began a stage, for CubeRotEnv and LayerOpEnv to
//!   reset from.
//! - [`VecEnv`]: many environments stepped on a thread pool, each with its own `MjData`.
//! - [`EnvSettings`] and [`EnvSpec`]: an environment as settings, checked once, whether they
//!   come from the command line, a recipe or Python.
//!
//! Dynamics follow Gymnasium-Robotics' hand environments: an action in [-1, 1]^20 maps onto
//! the actuators' control ranges as absolute joint targets, a control step is 20 substeps of
//! 0.002 s, an episode is 100 control steps, and the hand starts at its model pose.

pub mod goal;
mod hand_object;
pub mod layer;
pub mod random;
pub mod rot;
pub mod spec;
pub mod starts;
pub mod vec_env;

use std::sync::Arc;

pub use dexcube_sim::SimError;
pub use goal::{Goal, GoalLead, LayerGoal, RotGoal, RotMode};
pub use hand_object::{
    BASE_OBSERVATION, DROP_DEPTH, EpisodeSettings, OBJECT_POSITION, ObjectKind, SETTLE_STEPS, View,
    base_observation, in_object_frame, is_dropped, is_square, resting_point, set_down,
};
pub use layer::{CubeLayer, LayerMove, LayerOpEnv};
pub use rot::{CubeRotEnv, achieved_goal, cube_misalignment, pose_goal, rot_observation};
pub use spec::{EnvMaker, EnvSettings, EnvSpec, PAPER_ANGLE_THRESHOLD, Skill, StartsSetting};
pub use starts::{RecordedFailure, RecordedStart, StartMix, StartPick};
pub use vec_env::VecEnv;

/// Control steps in an episode (the paper's 100).
pub const EPISODE_STEPS: usize = 100;

/// How often a policy acts: every so many physics substeps of 2 ms, the paper's 20 or fewer
/// for a faster rate. An episode has as many more control steps at a faster rate, so that
/// it lasts the paper's 4 simulated seconds at any rate. Only a number that divides 20 makes
/// one, so every holder of a rate can run it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ControlRate {
    substeps: usize,
}

impl ControlRate {
    /// Gymnasium-Robotics' and the paper's: 20 substeps, 100 steps an episode.
    pub const PAPER: ControlRate = ControlRate {
        substeps: dexcube_sim::SUBSTEPS,
    };

    /// Acting every `substeps` physics substeps; fails unless `substeps` divides 20.
    pub fn every(substeps: usize) -> Result<ControlRate, String> {
        use dexcube_sim::SUBSTEPS;
        if !SUBSTEPS.is_multiple_of(substeps) {
            return Err(format!(
                "{substeps} substeps per control step: use a number that divides the paper's \
                 {SUBSTEPS} (1, 2, 4, 5, 10 or 20)"
            ));
        }
        Ok(ControlRate { substeps })
    }

    /// Physics substeps per control step.
    pub fn substeps(self) -> usize {
        self.substeps
    }

    /// Control steps in an episode: the paper's 100 at its rate.
    pub fn episode_steps(self) -> usize {
        EPISODE_STEPS * dexcube_sim::SUBSTEPS / self.substeps
    }
}

impl std::fmt::Display for ControlRate {
    /// The number of substeps, as `--control-substeps` takes it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.substeps)
    }
}

impl std::str::FromStr for ControlRate {
    type Err = String;
    fn from_str(text: &str) -> Result<ControlRate, String> {
        let substeps = text
            .parse::<usize>()
            .map_err(|_| format!("'{text}' is not a whole number of substeps"))?;
        ControlRate::every(substeps)
    }
}

/// An observation in Gymnasium-Robotics' three parts.
#[derive(Clone, Debug, PartialEq)]
pub struct Observation {
    pub observation: Vec<f64>,
    pub achieved_goal: Vec<f64>,
    pub desired_goal: Vec<f64>,
}

/// What `step` and `reset` report besides the observation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Info {
    pub is_success: bool,
    /// Distance from the goal position, metres (0 where the goal has no position).
    pub position_error: f64,
    /// Angle from the goal orientation or layer angle, radians.
    pub angle_error: f64,
    /// The object fell below the palm.
    pub dropped: bool,
    /// The physics blew up during this step; the environment must be reset.
    pub physics_error: Option<SimError>,
}

/// One step's outcome.
#[derive(Clone, Debug, PartialEq)]
pub struct Transition {
    pub observation: Observation,
    pub reward: f64,
    /// The episode ended in failure: the object dropped or the physics blew up.
    pub terminated: bool,
    /// The episode reached its step limit.
    pub truncated: bool,
    pub info: Info,
}

/// Sizes of the spaces, for building networks from an environment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Spaces {
    pub observation: usize,
    pub goal: usize,
    pub action: usize,
}

/// Gymnasium-Robotics' goal-conditioned environment contract.
pub trait GoalEnv: Send {
    fn spaces(&self) -> Spaces;

    /// The success test and reward, shareable with a replay buffer.
    fn goal(&self) -> Arc<dyn Goal>;

    /// Starts an episode. A seed re-seeds the environment's generator; `None` continues it.
    fn reset(&mut self, seed: Option<u64>) -> (Observation, Info);

    /// Applies an action (each component in [-1, 1]) for one step.
    fn step(&mut self, action: &[f64]) -> Transition;
}

/// Any goal environment behind a box is one too, so that a run whose phases build different
/// environments can step them alike.
impl GoalEnv for Box<dyn GoalEnv> {
    fn spaces(&self) -> Spaces {
        (**self).spaces()
    }

    fn goal(&self) -> Arc<dyn Goal> {
        (**self).goal()
    }

    fn reset(&mut self, seed: Option<u64>) -> (Observation, Info) {
        (**self).reset(seed)
    }

    fn step(&mut self, action: &[f64]) -> Transition {
        (**self).step(action)
    }
}

/// An environment backed by a MuJoCo simulation, for rendering and inspection.
pub trait SimulatedEnv: GoalEnv {
    fn sim(&self) -> &dexcube_sim::Sim;
    fn sim_mut(&mut self) -> &mut dexcube_sim::Sim;

    /// Called right after a fresh reset (one not from a recorded start): the start that
    /// `reset_from` restores this episode from, bit for bit (its physics state and goal; not
    /// marked failed). `eval-stage --record-starts` keeps them, so that training can draw
    /// again the fresh placements a policy failed from. CubeRotEnv's goal holds through an
    /// episode, so for Stage 1 it is also a start at any later step: `eval-stage
    /// --record-closest` keeps the one nearest the pose. LayerOpEnv's holds the angle the
    /// layer has turned since the episode began and the face whose layer turns, so that a
    /// later step is a start too (`eval-stage --record-starts --after-gesture`).
    fn fresh_start(&self) -> RecordedStart;
}
