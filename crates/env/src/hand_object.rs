//! What CubeRotEnv and LayerOpEnv share: the hand with an object on its palm, the first 61
//! observations and what a policy may be shown beyond its stage's ([`View`]), placing the
//! object at reset, the drop test, and turning a goal's verdict into a `Transition`.

use std::sync::Arc;

use dexcube_sim::cube::{ALIGNED_TOLERANCE, CubeState};
use dexcube_sim::rotation::{self, Quat};
use dexcube_sim::{
    GRIP_PARTS, HAND_ACTUATORS, HAND_JOINTS, PhysicsScales, Pose, Scene, SceneKind, Sim,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::goal::Goal;
use crate::random::standard_normal;
use crate::{ControlRate, Info, Observation, Transition};

/// Observations shared by both environments: joint angles 24, joint velocities 24, object
/// position 3, orientation 4, velocity 3, angular velocity 3.
pub const BASE_OBSERVATION: usize = 61;

/// Where the object's position (x, y, z in world metres) begins in those observations, after
/// the joint angles and velocities.
pub const OBJECT_POSITION: usize = 2 * HAND_JOINTS;

/// What a policy is shown beyond its stage's paper observations, appended after them in this
/// order; both parts are for the physical cube. A trained policy's view is told from the size
/// of its observation ([`View::after`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct View {
    /// The cube's misalignment in units of the good state's tolerance (one number): the part
    /// of a square goal's achieved goal that the paper's observations do not show.
    pub misalignment: bool,
    /// The hand's grip on the cube ([`Sim::grip`]: the normal force in newtons with which the
    /// thumb, each finger and the palm press on it; six numbers), which the joint angles
    /// show only through the cube's motion.
    pub grip: bool,
}

impl View {
    /// The paper's observations alone.
    pub const PAPER: View = View {
        misalignment: false,
        grip: false,
    };

    const ALL: [View; 4] = [
        View::PAPER,
        View {
            misalignment: true,
            grip: false,
        },
        View {
            misalignment: false,
            grip: true,
        },
        View {
            misalignment: true,
            grip: true,
        },
    ];

    /// How many numbers this view appends to the paper's.
    pub fn size(self) -> usize {
        usize::from(self.misalignment) + if self.grip { GRIP_PARTS.len() } else { 0 }
    }

    /// The view of a policy whose observation has `size` inputs after its stage's `paper`
    /// ones; `None` if no view has that size.
    pub fn after(paper: usize, size: usize) -> Option<View> {
        let extra = size.checked_sub(paper)?;
        View::ALL.into_iter().find(|view| view.size() == extra)
    }

    /// Whether this view's numbers are the leading part of `wider`'s, so that a policy trained
    /// with this view can read its inputs from the start of `wider`'s observation (views append
    /// the misalignment first, then the grip).
    pub fn leads(self, wider: View) -> bool {
        let misalignment_only = View {
            misalignment: true,
            grip: false,
        };
        self == View::PAPER || self == wider || (self == misalignment_only && wider.misalignment)
    }

    /// What the view adds, in words for labels: `None` for the paper's, else "misalignment",
    /// "grip" or "misalignment and grip".
    pub fn name(self) -> Option<&'static str> {
        match (self.misalignment, self.grip) {
            (false, false) => None,
            (true, false) => Some("misalignment"),
            (false, true) => Some("grip"),
            (true, true) => Some("misalignment and grip"),
        }
    }

    /// Appends what this view shows of `sim` to `observation`; `misalignment` gives the
    /// cube's (radians), asked for only if the view shows it.
    pub fn extend(self, observation: &mut Vec<f64>, sim: &Sim, misalignment: impl FnOnce() -> f64) {
        if self.misalignment {
            observation.push(misalignment() / ALIGNED_TOLERANCE);
        }
        if self.grip {
            observation.extend(sim.grip());
        }
    }
}

/// How far below its resting point the object must fall to count as dropped, metres.
pub const DROP_DEPTH: f64 = 0.05;

/// Control steps with a neutral action that let a newly placed object settle, as
/// Gymnasium-Robotics does. Every episode starts from the hand so settled.
pub const SETTLE_STEPS: usize = 10;

/// Standard deviation of the object's start position around its resting point, metres
/// (Gymnasium-Robotics' 0.005).
const START_POSITION_NOISE: f64 = 0.005;

/// The object on the palm, by scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ObjectKind {
    /// The physical 2x2x2 cube (`cube` scene): what the operator turns. Both environments.
    Cube,
    /// A two-layer block on one hinge (`layer` scene): LayerOpEnv, quicker to simulate.
    Block,
    /// A rigid 5 cm cube (`rot` scene): CubeRotEnv, quicker to simulate.
    Rigid,
}

impl ObjectKind {
    pub const ALL: [ObjectKind; 3] = [ObjectKind::Cube, ObjectKind::Block, ObjectKind::Rigid];

    pub fn name(self) -> &'static str {
        match self {
            ObjectKind::Cube => "cube",
            ObjectKind::Block => "block",
            ObjectKind::Rigid => "rigid",
        }
    }

    pub fn scene(self) -> SceneKind {
        match self {
            ObjectKind::Cube => SceneKind::Cube,
            ObjectKind::Block => SceneKind::Layer,
            ObjectKind::Rigid => SceneKind::Rot,
        }
    }
}

impl std::str::FromStr for ObjectKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        ObjectKind::ALL
            .into_iter()
            .find(|o| o.name() == s)
            .ok_or_else(|| format!("unknown object '{s}': use cube, block or rigid"))
    }
}

pub struct HandObject {
    pub sim: Sim,
    pub rng: ChaCha8Rng,
    /// Where the object comes to rest on the palm, and CubeRotEnv's target position.
    pub resting: [f64; 3],
    pub steps: usize,
    pub settings: EpisodeSettings,
}

/// How either environment runs its episodes beyond the scene: the paper's
/// ([`EpisodeSettings::PAPER`]) unless set ([`CubeRotEnv::with_settings`],
/// [`LayerOpEnv::with_settings`]).
///
/// [`CubeRotEnv::with_settings`]: crate::CubeRotEnv::with_settings
/// [`LayerOpEnv::with_settings`]: crate::LayerOpEnv::with_settings
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EpisodeSettings {
    /// How often a policy acts. Placing and settling keep the paper's rate, so every rate
    /// starts from the same placements.
    pub rate: ControlRate,
    /// The most an actuator's target may move in one control step, in action units (the
    /// action range is 2 wide); `None` (the paper's) lets it jump anywhere at once.
    pub action_slew: Option<f64>,
    /// How far each episode's physics is varied ([`HandObject::begin_episode`]); 0, the
    /// paper's, keeps the scene's own.
    pub physics_spread: f64,
    /// Control steps in an episode where set; `None` (the paper's) is the rate's 4 simulated
    /// seconds ([`ControlRate::episode_steps`]).
    pub episode_steps: Option<usize>,
}

impl EpisodeSettings {
    /// The paper's: its control rate, targets free to jump, the scene's own physics and
    /// episodes of 4 simulated seconds.
    pub const PAPER: EpisodeSettings = EpisodeSettings {
        rate: ControlRate::PAPER,
        action_slew: None,
        physics_spread: 0.0,
        episode_steps: None,
    };

    /// Control steps in an episode.
    pub fn episode_length(&self) -> usize {
        self.episode_steps.unwrap_or(self.rate.episode_steps())
    }
}

impl HandObject {
    /// A hand with its object, and the object's resting point: where it settles from the
    /// scene's start with a neutral action.
    pub fn new(scene: Arc<Scene>) -> HandObject {
        let mut sim = Sim::new(scene);
        let start = sim.object_pose();
        settle(&mut sim);
        let resting = if sim.object_pose().position[2] > start.position[2] - DROP_DEPTH {
            sim.object_pose().position
        } else {
            start.position
        };
        HandObject {
            sim,
            rng: ChaCha8Rng::seed_from_u64(0),
            resting,
            steps: 0,
            settings: EpisodeSettings::PAPER,
        }
    }

    /// Begins an episode: re-seeds the generator if asked, then, with a physics spread s,
    /// draws the episode's friction, object mass and damping scales from it, each
    /// log-uniform between 1/(1 + s) and 1 + s ([`Sim::set_physics_scales`]).
    pub fn begin_episode(&mut self, seed: Option<u64>) {
        if let Some(seed) = seed {
            self.rng = ChaCha8Rng::seed_from_u64(seed);
        }
        if self.settings.physics_spread > 0.0 {
            let (spread, rng) = (self.settings.physics_spread, &mut self.rng);
            let mut scale = || (1.0 + spread).powf(rng.random_range(-1.0..=1.0));
            let scales = PhysicsScales {
                friction: scale(),
                object_mass: scale(),
                damping: scale(),
            };
            self.sim.set_physics_scales(scales);
        }
    }

    /// Resets the hand and puts the object on the palm with `orientation`, near the resting
    /// point, then lets it settle ([`set_down`]).
    pub fn place(&mut self, orientation: impl Fn(&mut ChaCha8Rng) -> Quat) {
        let (resting, rng) = (self.resting, &mut self.rng);
        set_down(&mut self.sim, resting[2], |sim| {
            sim.reset();
            let mut position = resting;
            for p in &mut position {
                *p += START_POSITION_NOISE * standard_normal(rng);
            }
            Pose {
                position,
                orientation: orientation(rng),
            }
        });
        self.steps = 0;
    }

    pub fn dropped(&self) -> bool {
        is_dropped(&self.sim, self.resting[2])
    }

    /// The 61 shared observations.
    pub fn base_observation(&self) -> Vec<f64> {
        base_observation(&self.sim)
    }

    /// One control step; returns a physics error if the state blew up (the simulation is then
    /// reset, and the episode must end).
    fn advance(&mut self, action: &[f64]) -> Option<dexcube_sim::SimError> {
        let mut clipped = [0.0; HAND_ACTUATORS];
        for (c, a) in clipped.iter_mut().zip(action) {
            *c = if a.is_finite() {
                a.clamp(-1.0, 1.0)
            } else {
                0.0
            };
        }
        if let Some(slew) = self.settings.action_slew {
            for (c, held) in clipped.iter_mut().zip(self.sim.action()) {
                *c = c.clamp(held - slew, held + slew);
            }
        }
        self.sim.set_action(&clipped);
        self.steps += 1;
        self.sim
            .step_substeps(self.settings.rate.substeps())
            .err()
            .inspect(|_| self.sim.reset())
    }

    /// One environment step: the action for a control step, then the observation `observe`
    /// makes and the goal's verdict on it.
    pub fn step(
        &mut self,
        action: &[f64],
        goal: &dyn Goal,
        observe: impl FnOnce(&HandObject) -> Observation,
    ) -> Transition {
        let error = self.advance(action);
        self.transition(observe(self), goal, error)
    }

    /// A transition from an observation and the goal's verdict on it.
    fn transition(
        &self,
        observation: Observation,
        goal: &dyn Goal,
        physics_error: Option<dexcube_sim::SimError>,
    ) -> Transition {
        let info = self.info(&observation, goal, physics_error);
        let reward = goal.compute_reward(&observation.achieved_goal, &observation.desired_goal);
        Transition {
            terminated: info.dropped || info.physics_error.is_some(),
            truncated: self.steps >= self.settings.episode_length(),
            observation,
            reward,
            info,
        }
    }

    pub fn info(
        &self,
        observation: &Observation,
        goal: &dyn Goal,
        physics_error: Option<dexcube_sim::SimError>,
    ) -> Info {
        let (achieved, desired) = (&observation.achieved_goal, &observation.desired_goal);
        let (position_error, angle_error) = goal.errors(achieved, desired);
        let dropped = self.dropped();
        Info {
            // A fallen object never counts, whatever its angle (LayerOpEnv's goal has no
            // position): the episode has failed.
            is_success: goal.is_success(achieved, desired) && !dropped && physics_error.is_none(),
            position_error,
            angle_error,
            dropped,
            physics_error,
        }
    }
}

/// The 61 observations both environments share, from any scene with an object on the hand:
/// joint angles, joint velocities, object position, orientation (w ≥ 0), velocity, angular
/// velocity. The operator feeds the trained policies the same from the physical cube.
pub fn base_observation(sim: &Sim) -> Vec<f64> {
    let pose = sim.object_pose();
    let (velocity, angular) = sim.object_velocity();
    let mut out = Vec::with_capacity(BASE_OBSERVATION + 1 + GRIP_PARTS.len());
    out.extend(sim.hand_angles());
    out.extend(sim.hand_velocities());
    out.extend(pose.position);
    out.extend(canonical(pose.orientation));
    out.extend(velocity);
    out.extend(angular);
    out
}

/// True once the object has fallen `DROP_DEPTH` below the height it rests at on the palm.
pub fn is_dropped(sim: &Sim, resting_z: f64) -> bool {
    sim.object_pose().position[2] < resting_z - DROP_DEPTH
}

/// Where a scene's object comes to rest on the palm: it settles from the scene's start with
/// a neutral action (or stays at its start if it would fall). Leaves `sim` reset.
pub fn resting_point(sim: &mut Sim) -> [f64; 3] {
    sim.reset();
    let start = sim.object_pose();
    settle(sim);
    let settled = sim.object_pose().position;
    sim.reset();
    if settled[2] > start.position[2] - DROP_DEPTH {
        settled
    } else {
        start.position
    }
}

/// How many times [`set_down`] tries before it keeps a bad landing.
const SET_DOWN_TRIES: usize = 10;

/// Sets the object down and lets it settle with the neutral action, as every episode starts:
/// `prepare` readies the simulation for a try and names the pose. Tries again, up to ten
/// times, if the physics blew up, the object fell `DROP_DEPTH` below `resting_z`, or it did
/// not land square (a physical cube with a layer knocked out of its good state: about one
/// landing in ten on a flat hand). False if every try failed.
pub fn set_down(sim: &mut Sim, resting_z: f64, mut prepare: impl FnMut(&mut Sim) -> Pose) -> bool {
    (0..SET_DOWN_TRIES).any(|_| {
        let pose = prepare(sim);
        sim.set_object_pose(&pose);
        sim.forward();
        settle(sim) && !is_dropped(sim, resting_z) && is_square(sim)
    })
}

/// Whether the object is square: a physical cube in its good state; any other object always.
pub fn is_square(sim: &Sim) -> bool {
    CubeState::read(sim).is_none_or(|cube| cube.is_aligned())
}

/// Lets the object settle with a neutral action; false if the physics blew up.
fn settle(sim: &mut Sim) -> bool {
    sim.set_action(&[0.0; HAND_ACTUATORS]);
    (0..SETTLE_STEPS).all(|_| sim.step().is_ok())
}

/// The same rotation with a non-negative real part.
pub fn canonical(q: Quat) -> Quat {
    if q[0] < 0.0 { q.map(|x| -x) } else { q }
}

/// Orientation `q` read in the object's frame relabelled by `g`, a rotation of the object onto
/// itself: q·g, with w ≥ 0.
pub fn relabelled(q: &Quat, g: &Quat) -> Quat {
    canonical(rotation::normalise(&rotation::mul(q, g)))
}

/// An observation of the object (the 61 shared ones first) read in its frame relabelled by
/// `g` ([`Goal::nearest_frame`]): the orientation q·g, and the angular velocity, which is in
/// the object's frame, turned by g⁻¹; the rest, world-frame or the frame's own, is the same.
pub fn in_object_frame(observation: &[f64], g: &Quat) -> Vec<f64> {
    let orientation = OBJECT_POSITION + 3;
    let angular = OBJECT_POSITION + 10;
    let mut seen = observation.to_vec();
    let q = &observation[orientation..orientation + 4];
    seen[orientation..orientation + 4].copy_from_slice(&relabelled(&[q[0], q[1], q[2], q[3]], g));
    let w = &observation[angular..angular + 3];
    let turned = rotation::rotate(&rotation::conj(g), [w[0], w[1], w[2]]);
    seen[angular..angular + 3].copy_from_slice(&turned);
    seen
}
