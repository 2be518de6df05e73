//! LayerOpEnv (Stage 2): turn one layer of a cube on the palm by a quarter turn.
//!
//! The layer belongs to one of two objects ([`ObjectKind`]): the physical 2x2x2 cube of the
//! `cube` scene (eight cubelets on ball joints, held in line by a detent), which is what the
//! operator turns, or a two-layer block on one hinge (the `layer` scene), twice as quick to
//! simulate.
//!
//! Observation (62): hand joint angles 24 and velocities 24, the object's position 3,
//! orientation 4, velocity 3 and angular velocity 3 (in its own frame), then the layer angle.
//! On the cube the policy may also be shown more ([`LayerOpEnv::with_view`]): the cube's
//! misalignment (63), in units of the good state's tolerance, the part of the achieved goal
//! that the square test reads and the 62 do not show, so that a side layer giving way under
//! the fingers is seen as it happens; and the hand's grip on the cube (six more).
//! On the block the orientation is its bottom layer's; on the cube it is the orientation of
//! the layer that stays (the one behind the turning face), taken among the cube's 24
//! symmetric frames as the one nearest the move's base orientation: a 2x2x2 looks the same
//! from every side, so the policy need not know which cubelet is which. The operator feeds
//! its Stage 2 policy the same view ([`CubeLayer`]). Goal (1): the target angle between the
//! layers, radians, counter-clockwise seen from outside the turning layer (so U is -π/2, U'
//! is +π/2); on the cube it is counted from the episode's start, unwrapped. With
//! [`LayerGoal::square`] the goal has a second part, the cube's misalignment (desired 0), and
//! success also needs the cube left in its good state: the paper's test reads only the
//! turned layer, and a policy trained on it learns to push a side layer part-way round.
//!
//! Six variants, as in the paper: the turning layer faces up (U), right (+x, R) or front
//! (-y, F), and turns clockwise (U, R, F) or counter-clockwise (U', R', F'). What is sampled,
//! exactly: at reset the object is placed with its turning layer facing the variant's
//! direction (on the cube, any of its six faces, chosen uniformly), at a uniformly random
//! angle about that direction, at the resting point plus N(0, 5 mm) noise, with its layers
//! aligned, and left to settle. For training the goal angle is uniform in [0, π/2]
//! (counter-clockwise) or [-π/2, 0] (clockwise), as the authors did, so HER sees
//! intermediate goals; for evaluation it is exactly ±π/2. With recorded starts
//! ([`LayerOpEnv::with_starts`]) a reset may instead restore where the operator handed Stage 2
//! the cube, for U' (the move the operator turns).

use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;

use dexcube_cube::Face;
use dexcube_sim::cube::{CubeState, face_toward, turn_face_by};
use dexcube_sim::rotation::{self, Quat};
use dexcube_sim::scene::{JointAddress, ObjectJoints};
use dexcube_sim::{Scene, Sim, SimError};
use rand::Rng;

use crate::goal::{Goal, LayerGoal, wrap_angle};
use crate::hand_object::{
    BASE_OBSERVATION, EpisodeSettings, HandObject, ObjectKind, View, canonical,
};
use crate::starts::{RecordedStart, StartMix};
use crate::{GoalEnv, Info, Observation, SimulatedEnv, Spaces, Transition};

/// Which layer faces where, and which way it turns.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LayerMove {
    U,
    UPrime,
    R,
    RPrime,
    F,
    FPrime,
}

impl LayerMove {
    pub const ALL: [LayerMove; 6] = [
        LayerMove::U,
        LayerMove::UPrime,
        LayerMove::R,
        LayerMove::RPrime,
        LayerMove::F,
        LayerMove::FPrime,
    ];

    pub fn name(self) -> &'static str {
        ["U", "U'", "R", "R'", "F", "F'"][self as usize]
    }

    /// +1 for a counter-clockwise (primed) turn, -1 for a clockwise one.
    pub fn direction(self) -> f64 {
        if (self as usize) % 2 == 1 { 1.0 } else { -1.0 }
    }

    /// The world direction the turning layer faces.
    pub fn facing(self) -> [f64; 3] {
        match self {
            LayerMove::U | LayerMove::UPrime => [0.0, 0.0, 1.0],
            LayerMove::R | LayerMove::RPrime => [1.0, 0.0, 0.0],
            LayerMove::F | LayerMove::FPrime => [0.0, -1.0, 0.0],
        }
    }

    /// A block orientation that points its hinge axis (block z) along `facing`.
    pub fn base_orientation(self) -> Quat {
        let h = FRAC_PI_2;
        match self {
            LayerMove::U | LayerMove::UPrime => rotation::IDENTITY,
            LayerMove::R | LayerMove::RPrime => rotation::about([0.0, 1.0, 0.0], h),
            LayerMove::F | LayerMove::FPrime => rotation::about([1.0, 0.0, 0.0], h),
        }
    }
}

impl std::str::FromStr for LayerMove {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.replace('’', "'");
        LayerMove::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("unknown layer move '{s}': use one of U U' R R' F F'"))
    }
}

/// Whether goal angles are sampled over the whole quarter turn or set to it exactly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayerGoals {
    Training,
    Evaluation,
}

/// Stage 2's view of the physical cube, shared by LayerOpEnv and the operator: the layer
/// that faces `facing` at the start turns against the layer behind it. Keeps the turned
/// angle unwrapped across readings (the cube's own reading wraps at ±45°).
#[derive(Clone, Debug)]
pub struct CubeLayer {
    base: Quat,
    face: Face,
    last: f64,
    turned: f64,
    view: View,
}

impl CubeLayer {
    /// Starts counting from the cube as it is, with the layer facing `facing` (world) as the
    /// one that turns; `base` is the orientation the observed frame is kept nearest to.
    /// `None` if the simulation is not of the `cube` scene.
    pub fn start(sim: &Sim, facing: [f64; 3], base: Quat) -> Option<CubeLayer> {
        CubeLayer::resume(sim, &[], facing, base)
    }

    /// Goes on counting from a recorded start's `goal` (see [`CubeLayer::start_goal`]): the
    /// layer of the face it names turns, counted from the angle it had turned. A goal that
    /// names no face (a fresh start's, or one recorded before session 54) turns the face now
    /// toward `facing`, as such a start did unless the cube had tipped since its stage began.
    /// `None` if the simulation is not of the `cube` scene.
    pub fn resume(sim: &Sim, goal: &[f64], facing: [f64; 3], base: Quat) -> Option<CubeLayer> {
        let state = CubeState::read(sim)?;
        let named = goal
            .get(2)
            .filter(|code| code.fract() == 0.0 && **code >= 0.0)
            .and_then(|&code| Face::ALL.get(code as usize));
        let face = named
            .copied()
            .unwrap_or_else(|| face_toward(&state.pose().orientation, facing));
        Some(CubeLayer {
            base,
            face,
            last: state.layer_angle(face),
            turned: goal.get(1).copied().unwrap_or(0.0),
            view: View::PAPER,
        })
    }

    /// The goal a recorded start of Stage 2 holds ([`RecordedStart::goal`]): the layer angle
    /// to turn, the angle the layer has turned so far, and the face whose layer turns (its
    /// place in `Face::ALL`), since a start recorded in mid-stage may find the cube tipped so
    /// that another face is up.
    pub fn start_goal(&self, desired: f64) -> Vec<f64> {
        vec![desired, self.turned, self.face as usize as f64]
    }

    /// The same, showing `view` after the layer angle.
    pub fn with_view(mut self, view: View) -> CubeLayer {
        self.view = view;
        self
    }

    /// How many numbers Stage 2 observes without a view beyond the paper's (the 61, then the
    /// layer angle); a trained policy's view is told from how many more it takes
    /// ([`View::after`]: 63 with the misalignment, 68 with the grip, 69 with both).
    pub const PAPER_OBSERVATION: usize = BASE_OBSERVATION + 1;

    /// How many inputs this view gives the policy.
    pub fn observation_size(&self) -> usize {
        CubeLayer::PAPER_OBSERVATION + self.view.size()
    }

    /// The observations: the 62 (the layer angle turned so far last), then what the view
    /// shows beyond them.
    pub fn observe(&mut self, sim: &Sim) -> Vec<f64> {
        self.observe_reading(sim, &read_cube(sim), None)
    }

    /// Follows the layer angle to `sim`'s state without building an observation, for a
    /// watcher that needs only the angle; it must be called as often as the policy observes,
    /// every control step, for the angle to unwrap the same way.
    pub fn follow(&mut self, sim: &Sim) {
        self.follow_reading(&read_cube(sim));
    }

    /// Readings wrap at ±45°: accumulates the change since the last reading, brought into
    /// ±45°.
    fn follow_reading(&mut self, state: &CubeState) {
        let now = state.layer_angle(self.face);
        let change = now - self.last;
        self.turned += change - FRAC_PI_2 * (change / FRAC_PI_2).round();
        self.last = now;
    }

    /// The same from `state`, a reading of the cube in `sim` already taken, and its
    /// `misalignment` if that is already worked out (it is read from `state` only if this
    /// view shows it).
    fn observe_reading(
        &mut self,
        sim: &Sim,
        state: &CubeState,
        misalignment: Option<f64>,
    ) -> Vec<f64> {
        self.follow_reading(state);
        let (frame, spin) = state.layer_behind(self.face);
        let (symmetry, _) = rotation::snap_to_cube(
            &rotation::mul(&rotation::conj(&frame), &self.base),
            rotation::cube_group(),
        );
        let seen = canonical(rotation::normalise(&rotation::mul(&frame, &symmetry)));
        let (velocity, _) = sim.object_velocity();
        let mut out = Vec::with_capacity(self.observation_size());
        out.extend(sim.hand_angles());
        out.extend(sim.hand_velocities());
        out.extend(state.pose().position);
        out.extend(seen);
        out.extend(velocity);
        out.extend(rotation::rotate(&rotation::conj(&seen), spin));
        out.push(self.turned);
        self.view.extend(&mut out, sim, || {
            misalignment.unwrap_or_else(|| state.misalignment())
        });
        out
    }

    /// Accounts for a turn by `change` made outside the physics (a kinematic turn may jump
    /// past the ±45° within which readings are unwrapped).
    fn turned_by(&mut self, sim: &Sim, change: f64) {
        if let Some(state) = CubeState::read(sim) {
            self.last = state.layer_angle(self.face);
            self.turned += change;
        }
    }

    /// The angle turned since the start, as of the last observation.
    pub fn turned(&self) -> f64 {
        self.turned
    }
}

/// The layer of the object and how it is read.
enum Layer {
    Block { hinge: JointAddress },
    Cube(CubeLayer),
}

pub struct LayerOpEnv {
    hand: HandObject,
    layer_move: LayerMove,
    goals: LayerGoals,
    goal: Arc<LayerGoal>,
    desired: f64,
    layer: Layer,
    starts: Option<StartMix>,
}

impl LayerOpEnv {
    pub fn new(
        object: ObjectKind,
        layer_move: LayerMove,
        goals: LayerGoals,
    ) -> Result<LayerOpEnv, SimError> {
        Ok(LayerOpEnv::with_scene(
            Scene::load(object.scene())?,
            layer_move,
            goals,
        ))
    }

    /// A LayerOpEnv over an already loaded `cube` or `layer` scene. Panics on another scene.
    pub fn with_scene(scene: Arc<Scene>, layer_move: LayerMove, goals: LayerGoals) -> LayerOpEnv {
        let hand = HandObject::new(scene.clone());
        let layer = match *scene.object() {
            ObjectJoints::Layer { hinge, .. } => Layer::Block { hinge },
            ObjectJoints::Cube { .. } => Layer::Cube(
                CubeLayer::start(
                    &hand.sim,
                    layer_move.facing(),
                    layer_move.base_orientation(),
                )
                .expect("a cube scene"),
            ),
            ObjectJoints::Rot { .. } => panic!("LayerOpEnv needs the cube or layer scene"),
        };
        LayerOpEnv {
            hand,
            layer_move,
            goals,
            goal: Arc::new(LayerGoal::default()),
            desired: layer_move.direction() * FRAC_PI_2,
            layer,
            starts: None,
        }
    }

    pub fn layer_move(&self) -> LayerMove {
        self.layer_move
    }

    /// The angle between the layers: on the block in (-π, π], on the cube as turned since
    /// the episode's start.
    pub fn layer_angle(&self) -> f64 {
        match &self.layer {
            Layer::Block { hinge } => block_angle(&self.hand, *hinge),
            Layer::Cube(tracker) => tracker.turned(),
        }
    }

    /// Turns the layer kinematically to `angle` (for tests and demonstrations).
    pub fn set_layer_angle(&mut self, angle: f64) {
        let change = angle - self.layer_angle();
        match &mut self.layer {
            Layer::Block { hinge } => {
                let data = self.hand.sim.data_mut();
                data.qpos_mut()[hinge.qpos] = angle;
                data.qvel_mut()[hinge.dof] = 0.0;
            }
            Layer::Cube(tracker) => {
                // The face named as seen in the world, which is where the move's layer faces.
                let world_face = face_toward(&rotation::IDENTITY, self.layer_move.facing());
                turn_face_by(&mut self.hand.sim, world_face, change);
                tracker.turned_by(&self.hand.sim, change);
            }
        }
        self.hand.sim.forward();
    }

    pub fn set_desired_goal(&mut self, angle: f64) {
        self.desired = angle;
    }

    /// The same environment resetting from recorded starts if `mix` is given (the operator's
    /// Stage 2 starts on the cube, recorded with the top layer to turn), as its pick says,
    /// rather than from a fresh placement. A start that does not fit this scene falls back
    /// to a fresh placement.
    pub fn with_starts(mut self, mix: Option<StartMix>) -> LayerOpEnv {
        self.starts = mix;
        self
    }

    /// Starts an episode from a recorded start, counting the layer that faces the move's
    /// direction from the angle it had turned when recorded, with a goal drawn as at any
    /// reset; fails, leaving the simulation as it was, if the start's physics state does not
    /// fit this scene.
    pub fn reset_from(&mut self, start: &RecordedStart) -> Result<(Observation, Info), SimError> {
        self.hand.sim.restore_physics_state(&start.state)?;
        self.hand.steps = 0;
        Ok(self.first_observation(&start.goal))
    }

    /// Begins counting the layer from the object as it now lies, or as a recorded start's
    /// `goal` says (the face that turns, and the angle it has turned: [`CubeLayer::resume`];
    /// a fresh reset's is empty), draws the goal, and gives the episode's first observation
    /// and its info.
    fn first_observation(&mut self, goal: &[f64]) -> (Observation, Info) {
        let (facing, base) = (self.layer_move.facing(), self.layer_move.base_orientation());
        if let Layer::Cube(tracker) = &mut self.layer {
            *tracker = CubeLayer::resume(&self.hand.sim, goal, facing, base)
                .expect("a cube scene")
                .with_view(tracker.view);
        }
        let size = match self.goals {
            LayerGoals::Training => self.hand.rng.random_range(0.0..=FRAC_PI_2),
            LayerGoals::Evaluation => FRAC_PI_2,
        };
        self.desired = self.layer_move.direction() * size;
        let observation = self.layer.observe(&self.hand, &self.goal, self.desired);
        let info = self.hand.info(&observation, self.goal.as_ref(), None);
        (observation, info)
    }

    /// The same environment showing the policy `view` beyond the paper's 62 (see the
    /// module's doc). Panics if it shows more than the paper's on the block: the views are
    /// for the physical cube.
    pub fn with_view(mut self, view: View) -> LayerOpEnv {
        match &mut self.layer {
            Layer::Cube(tracker) => tracker.view = view,
            Layer::Block { .. } => assert!(
                view == View::PAPER,
                "the views beyond the paper's are for the physical cube"
            ),
        }
        self
    }

    /// The same environment running its episodes as `settings` say rather than as the paper
    /// does: another control rate, a limit on how fast the actuators' targets move, varied
    /// physics, another episode length.
    pub fn with_settings(mut self, settings: EpisodeSettings) -> LayerOpEnv {
        self.hand.settings = settings;
        self
    }

    /// The same environment judged by `goal`, e.g. [`LayerGoal::square`] to also need the
    /// cube left in its good state.
    pub fn with_goal(mut self, goal: LayerGoal) -> LayerOpEnv {
        self.goal = Arc::new(goal);
        self
    }
}

impl Layer {
    /// The observations (62, and what the view shows beyond them) and the goals: the layer
    /// angle achieved, and with a goal that needs the good state, the cube's misalignment
    /// (none on the block).
    fn observe(&mut self, hand: &HandObject, goal: &LayerGoal, desired: f64) -> Observation {
        let (observation, misalignment) = match self {
            Layer::Block { hinge } => {
                let mut observation = hand.base_observation();
                observation.push(block_angle(hand, *hinge));
                (observation, 0.0)
            }
            Layer::Cube(tracker) => {
                // One reading of the cube, and of its misalignment, serves the observation
                // and the good state.
                let state = read_cube(&hand.sim);
                let misalignment = goal.square_threshold.map(|_| state.misalignment());
                (
                    tracker.observe_reading(&hand.sim, &state, misalignment),
                    misalignment.unwrap_or(0.0),
                )
            }
        };
        Observation {
            achieved_goal: goal.achieved(observation[BASE_OBSERVATION], misalignment),
            desired_goal: goal.desired(desired),
            observation,
        }
    }
}

/// Reads the cube of a scene that holds one (a `Layer::Cube` or a started `CubeLayer`).
fn read_cube(sim: &Sim) -> CubeState {
    let Some(state) = CubeState::read(sim) else {
        unreachable!("a CubeLayer is only started on a cube scene")
    };
    state
}

fn block_angle(hand: &HandObject, hinge: JointAddress) -> f64 {
    wrap_angle(hand.sim.data().qpos()[hinge.qpos])
}

impl SimulatedEnv for LayerOpEnv {
    fn sim(&self) -> &dexcube_sim::Sim {
        &self.hand.sim
    }

    fn sim_mut(&mut self) -> &mut dexcube_sim::Sim {
        &mut self.hand.sim
    }

    /// The goal holds the quarter turn asked for, and on the physical cube the angle its
    /// layer has turned since the episode began (none right after a fresh reset) and the face
    /// whose layer turns ([`CubeLayer::start_goal`]); the block's hinge is read whole, so
    /// none there.
    fn fresh_start(&self) -> RecordedStart {
        let goal = match &self.layer {
            Layer::Cube(tracker) => tracker.start_goal(self.desired),
            Layer::Block { .. } => vec![self.desired, 0.0],
        };
        RecordedStart {
            state: self.hand.sim.physics_state(),
            goal,
            failed: false,
        }
    }
}

impl GoalEnv for LayerOpEnv {
    fn spaces(&self) -> Spaces {
        Spaces {
            observation: match &self.layer {
                Layer::Block { .. } => CubeLayer::PAPER_OBSERVATION,
                Layer::Cube(tracker) => tracker.observation_size(),
            },
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
        let (facing, base) = (self.layer_move.facing(), self.layer_move.base_orientation());
        // On the cube any face may be the turning one: its cubelets are alike. The block
        // draws nothing more, so its episodes stay as they were before the cube was an option.
        let any_face = matches!(self.layer, Layer::Cube(_));
        self.hand.place(|rng| {
            let spin = rotation::about(
                facing,
                rng.random_range(-std::f64::consts::PI..std::f64::consts::PI),
            );
            let face = if any_face {
                let group = rotation::cube_group();
                group[rng.random_range(0..group.len())]
            } else {
                rotation::IDENTITY
            };
            rotation::normalise(&rotation::mul(&rotation::mul(&spin, &base), &face))
        });
        self.first_observation(&[])
    }

    fn step(&mut self, action: &[f64]) -> Transition {
        let (layer, goal, desired) = (&mut self.layer, &self.goal, self.desired);
        self.hand.step(action, goal.as_ref(), |hand| {
            layer.observe(hand, goal, desired)
        })
    }
}
