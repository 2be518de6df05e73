//! CubeRotEnv (Stage 1): re-pose a cube on the palm (a rigid 5 cm cube, or the physical
//! 2x2x2 of the `cube` scene) so that a given face is up.
//!
//! Observation (61): hand joint angles 24, joint velocities 24, cube position 3, orientation
//! quaternion 4 (w first, w ≥ 0), linear velocity 3, angular velocity 3. Goal (7): target
//! position and quaternion. On the physical cube, with [`RotGoal::left_square`], the goal has
//! an eighth part, the cube's misalignment (desired 0), and success also needs the cube left
//! in its good state, as LayerOpEnv's square test does: the paper's test reads only the pose,
//! and a pose reached with a layer pushed part-way round must be restored before Stage 2.
//! With [`RotGoal::left_intact`] it also needs no layer turned from where it began: a layer
//! pushed a whole quarter round leaves the cube square but changes the puzzle, which spoils
//! the rest of the operator's plan. With [`RotGoal::ending_on_turn`] such a turn also ends
//! the episode as an absorbing failure, as a drop does.
//! On the physical cube the policy may also be shown more ([`CubeRotEnv::with_view`]): that
//! misalignment (62), in units of the good state's tolerance, as LayerOpEnv's view can be, the
//! part of the achieved goal that the 61 do not show; and the hand's grip on the cube (six
//! more), the force with which the thumb, each finger and the palm press on it.
//!
//! What is sampled, exactly: at reset the cube is placed at its resting point on the palm
//! plus N(0, 5 mm) noise on each coordinate, with an orientation drawn uniformly from SO(3)
//! (the paper's "arbitrary orientation"), and left to settle for 10 neutral control steps.
//! The goal is one of the paper's three target orientations, each with probability 1/3, at
//! the resting point. In the cube frame (x = R, y = B, z = U) those targets put U, R and B
//! on top. The paper names the third the F pose: with F facing -y, a +90° turn about x lifts
//! B, and turning B on top with U' is B', the same move as F' up to a whole-cube turn (a face
//! turn and the opposite face's turn in the same sense, each seen from its own side, move the
//! layers alike; the paper's "U and D' achieve the same result" means D).

use std::sync::Arc;

use dexcube_cube::Facelets;
use dexcube_sim::cube::{CubeState, read_puzzle};
use dexcube_sim::rotation::Quat;
use dexcube_sim::{Scene, SceneKind, Sim, SimError};
use rand::Rng;

use crate::goal::{Goal, RotGoal, RotMode};
use crate::hand_object::{
    BASE_OBSERVATION, EpisodeSettings, HandObject, View, base_observation, canonical,
};
use crate::random::uniform_rotation;
use crate::starts::{RecordedStart, StartMix};
use crate::{GoalEnv, Info, Observation, SimulatedEnv, Spaces, Transition};

/// The paper's three Stage 1 targets, `[w, x, y, z]`.
pub const PAPER_TARGETS: [Quat; 3] = [
    [1.0, 0.0, 0.0, 0.0],
    [
        std::f64::consts::FRAC_1_SQRT_2,
        0.0,
        -std::f64::consts::FRAC_1_SQRT_2,
        0.0,
    ],
    [
        std::f64::consts::FRAC_1_SQRT_2,
        std::f64::consts::FRAC_1_SQRT_2,
        0.0,
        0.0,
    ],
];

pub struct CubeRotEnv {
    hand: HandObject,
    goal: Arc<RotGoal>,
    desired: Vec<f64>,
    starts: Option<StartMix>,
    view: View,
    /// The cube's puzzle when the episode began, kept for a goal that needs it intact.
    puzzle_at_start: Option<Facelets>,
}

impl CubeRotEnv {
    /// A CubeRotEnv with the paper's thresholds in the given mode.
    pub fn new(mode: RotMode) -> Result<CubeRotEnv, SimError> {
        Ok(CubeRotEnv::with_scene(
            Scene::load(SceneKind::Rot)?,
            RotGoal::paper(mode),
        ))
    }

    /// A CubeRotEnv over an already loaded `rot` or `cube` scene (shared between environments).
    pub fn with_scene(scene: Arc<Scene>, goal: RotGoal) -> CubeRotEnv {
        let hand = HandObject::new(scene);
        let desired = pose_goal(hand.resting, PAPER_TARGETS[0]);
        CubeRotEnv {
            hand,
            goal: Arc::new(goal),
            desired,
            starts: None,
            view: View::PAPER,
            puzzle_at_start: None,
        }
    }

    /// The same environment resetting from recorded starts if `mix` is given, as its pick
    /// says, rather than from a fresh placement. The starts must come from this environment's
    /// scene; one that does not fit falls back to a fresh placement.
    pub fn with_starts(mut self, mix: Option<StartMix>) -> CubeRotEnv {
        self.starts = mix;
        self
    }

    /// Starts an episode from a recorded start, with its goal pose; fails, leaving the
    /// simulation as it was, if the start's physics state does not fit this scene.
    pub fn reset_from(&mut self, start: &RecordedStart) -> Result<(Observation, Info), SimError> {
        self.hand.sim.restore_physics_state(&start.state)?;
        self.hand.steps = 0;
        self.desired = start.goal.clone();
        self.show_target();
        Ok(self.first_observation())
    }

    /// The episode's first observation and its info; notes the puzzle it begins with.
    fn first_observation(&mut self) -> (Observation, Info) {
        self.puzzle_at_start = self
            .goal
            .intact
            .then(|| read_puzzle(&self.hand.sim))
            .flatten();
        let (observation, _) = observe(
            &self.hand,
            &self.goal,
            &self.desired,
            self.view,
            self.puzzle_at_start.as_ref(),
        );
        let info = self.hand.info(&observation, self.goal.as_ref(), None);
        (observation, info)
    }

    /// The same environment judged by `goal`, e.g. [`RotGoal::left_square`] to also need the
    /// physical cube left in its good state.
    pub fn with_goal(mut self, goal: RotGoal) -> CubeRotEnv {
        self.goal = Arc::new(goal);
        self
    }

    /// The same environment showing the policy `view` beyond the paper's 61 (see the
    /// module's doc). Panics if it shows more than the paper's on the rigid cube: the views
    /// are for the physical cube.
    pub fn with_view(mut self, view: View) -> CubeRotEnv {
        assert!(
            view == View::PAPER || self.hand.sim.scene().object().cube_balls().is_some(),
            "the views beyond the paper's are for the physical cube"
        );
        self.view = view;
        self
    }

    /// The same environment running its episodes as `settings` say rather than as the paper
    /// does: another control rate, a limit on how fast the actuators' targets move, varied
    /// physics, another episode length.
    pub fn with_settings(mut self, settings: EpisodeSettings) -> CubeRotEnv {
        self.hand.settings = settings;
        self
    }

    /// How many numbers Stage 1 observes without a view beyond the paper's; a trained
    /// policy's view is told from how many more it takes ([`View::after`]: 62 with the
    /// misalignment, 67 with the grip, 68 with both).
    pub const PAPER_OBSERVATION: usize = BASE_OBSERVATION;

    /// Sets the goal pose (position, then quaternion) for the episode under way.
    pub fn set_desired_goal(&mut self, desired: &[f64]) {
        self.desired = desired.to_vec();
        self.show_target();
    }

    /// The palm's resting point, the target position.
    pub fn resting_point(&self) -> [f64; 3] {
        self.hand.resting
    }

    /// Turns the ghost cube beside the hand to the goal orientation.
    fn show_target(&mut self) {
        if let dexcube_sim::scene::ObjectJoints::Rot { target_mocap, .. } =
            self.hand.sim.scene().object()
        {
            let mocap = *target_mocap;
            self.hand.sim.data_mut().mocap_quat_mut()[mocap].copy_from_slice(&self.desired[3..7]);
        }
    }
}

/// The observations, with the cube's pose (observations 48 to 54) as the achieved goal, and
/// with a goal that needs the good state, the cube's misalignment after it, a quarter turn
/// more once a layer has turned from `puzzle_at_start` if the goal needs the cube intact.
/// The cube is read once a step, and only if the goal or the view needs it. Also says
/// whether a layer has turned (always false unless the goal needs the cube intact).
fn observe(
    hand: &HandObject,
    goal: &RotGoal,
    desired: &[f64],
    view: View,
    puzzle_at_start: Option<&Facelets>,
) -> (Observation, bool) {
    let read = goal.square_threshold.is_some() || view.misalignment;
    let cube = read.then(|| CubeState::read(&hand.sim)).flatten();
    // The rigid cube is always square.
    let misalignment = read.then(|| cube.as_ref().map_or(0.0, CubeState::misalignment));
    let observation = rot_observation(&hand.sim, view, misalignment);
    let turned = goal.intact
        && cube
            .as_ref()
            .zip(puzzle_at_start)
            .is_some_and(|(cube, start)| cube.turned_since(start));
    let quarter_if_turned = if turned {
        std::f64::consts::FRAC_PI_2
    } else {
        0.0
    };
    let achieved_misalignment = misalignment.unwrap_or(0.0) + quarter_if_turned;
    let observation = Observation {
        achieved_goal: goal.achieved(&observation[48..55], achieved_misalignment),
        desired_goal: goal.desired(desired),
        observation,
    };
    (observation, turned)
}

/// Stage 1's observations of the object in `sim`: the 61, then what `view` shows beyond them,
/// the cube's misalignment taken from `misalignment` (radians) if already read. The operator
/// feeds a trained policy the same.
pub fn rot_observation(sim: &Sim, view: View, misalignment: Option<f64>) -> Vec<f64> {
    let mut observation = base_observation(sim);
    view.extend(&mut observation, sim, || {
        misalignment.unwrap_or_else(|| cube_misalignment(sim))
    });
    observation
}

/// The physical cube's misalignment in `sim` (radians); 0 for the rigid cube, which is
/// always square.
pub fn cube_misalignment(sim: &Sim) -> f64 {
    CubeState::read(sim).map_or(0.0, |cube| cube.misalignment())
}

/// CubeRotEnv's achieved goal for the cube in `sim` at `pose` (position, then quaternion with
/// w ≥ 0): with a goal that needs the good state, the cube's misalignment after it, which is
/// read only then. Without the episode's start it cannot tell a turned layer, so a goal
/// that needs the cube intact is judged here as one that needs it square.
pub fn achieved_goal(goal: &RotGoal, sim: &Sim, pose: &[f64]) -> Vec<f64> {
    let misalignment = match goal.square_threshold {
        Some(_) => cube_misalignment(sim),
        None => 0.0,
    };
    goal.achieved(pose, misalignment)
}

/// A pose as CubeRotEnv's goal vector: position, then the quaternion with w ≥ 0.
pub fn pose_goal(position: [f64; 3], orientation: Quat) -> Vec<f64> {
    position
        .iter()
        .chain(canonical(orientation).iter())
        .copied()
        .collect()
}

impl SimulatedEnv for CubeRotEnv {
    fn sim(&self) -> &dexcube_sim::Sim {
        &self.hand.sim
    }

    fn sim_mut(&mut self) -> &mut dexcube_sim::Sim {
        &mut self.hand.sim
    }

    fn fresh_start(&self) -> RecordedStart {
        RecordedStart {
            state: self.hand.sim.physics_state(),
            goal: self.desired.clone(),
            failed: false,
        }
    }
}

impl GoalEnv for CubeRotEnv {
    fn spaces(&self) -> Spaces {
        Spaces {
            observation: CubeRotEnv::PAPER_OBSERVATION + self.view.size(),
            goal: self.goal.size(),
            action: dexcube_sim::HAND_ACTUATORS,
        }
    }

    fn goal(&self) -> Arc<dyn Goal> {
        self.goal.clone()
    }

    fn reset(&mut self, seed: Option<u64>) -> (Observation, Info) {
        self.hand.begin_episode(seed);
        if let Some(mix) = self.starts.clone()
            && let Some(start) = mix.pick(seed, &mut self.hand.rng)
            && let Ok(first) = self.reset_from(start)
        {
            return first;
        }
        self.hand.place(uniform_rotation);
        let pick = self.hand.rng.random_range(0..PAPER_TARGETS.len());
        self.desired = pose_goal(self.hand.resting, PAPER_TARGETS[pick]);
        self.show_target();
        self.first_observation()
    }

    fn step(&mut self, action: &[f64]) -> Transition {
        let (goal, desired, view) = (&self.goal, &self.desired, self.view);
        let start = self.puzzle_at_start.as_ref();
        let mut turned = false;
        let mut transition = self.hand.step(action, goal.as_ref(), |hand| {
            let (observation, turned_now) = observe(hand, goal, desired, view, start);
            turned = turned_now;
            observation
        });
        transition.terminated |= goal.turn_ends && turned;
        transition
    }
}

impl RotMode {
    pub fn name(self) -> &'static str {
        match self {
            RotMode::Paper => "paper",
            RotMode::Axis => "axis",
            RotMode::Pair => "pair",
        }
    }
}

impl std::str::FromStr for RotMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "paper" => Ok(RotMode::Paper),
            "axis" => Ok(RotMode::Axis),
            "pair" => Ok(RotMode::Pair),
            other => Err(format!(
                "unknown CubeRotEnv mode '{other}': use paper, axis or pair"
            )),
        }
    }
}
