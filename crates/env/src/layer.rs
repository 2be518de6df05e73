//! LayerOpEnv (Stage 2): turn one layer of a two-layer block by a quarter turn.
//!
//! Observation (62): the 61 of CubeRotEnv for the block (its bottom layer's pose) plus the
//! layer angle. Goal (1): the target angle between the layers, radians, counter-clockwise
//! seen from outside the turning layer (so U is -π/2, U' is +π/2).
//!
//! Six variants, as in the paper: the turning layer faces up (U), right (+x, R) or front
//! (-y, F), and turns clockwise (U, R, F) or counter-clockwise (U', R', F'). What is sampled,
//! exactly: at reset the block is placed with its turning layer facing the variant's
//! direction, at a uniformly random angle about that direction, at the resting point plus
//! N(0, 5 mm) noise, with its layers aligned, and left to settle. For training the goal angle
//! is uniform in [0, π/2] (counter-clockwise) or [-π/2, 0] (clockwise), as the authors did,
//! so HER sees intermediate goals; for evaluation it is exactly ±π/2.

use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;

use dexcube_sim::rotation::{self, Quat};
use dexcube_sim::scene::ObjectJoints;
use dexcube_sim::{Scene, SceneKind, SimError};
use rand::Rng;

use crate::goal::{Goal, LayerGoal, wrap_angle};
use crate::hand_object::HandObject;
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
    fn base_orientation(self) -> Quat {
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

pub struct LayerOpEnv {
    hand: HandObject,
    layer_move: LayerMove,
    goals: LayerGoals,
    goal: Arc<LayerGoal>,
    desired: f64,
    hinge: dexcube_sim::scene::JointAddress,
}

impl LayerOpEnv {
    pub fn new(layer_move: LayerMove, goals: LayerGoals) -> Result<LayerOpEnv, SimError> {
        Ok(LayerOpEnv::with_scene(
            Scene::load(SceneKind::Layer)?,
            layer_move,
            goals,
        ))
    }

    /// A LayerOpEnv over an already loaded `layer` scene. Panics if the scene is not one.
    pub fn with_scene(scene: Arc<Scene>, layer_move: LayerMove, goals: LayerGoals) -> LayerOpEnv {
        let ObjectJoints::Layer { hinge, .. } = *scene.object() else {
            panic!("LayerOpEnv needs the layer scene, not {}", scene.kind());
        };
        let hand = HandObject::new(scene);
        LayerOpEnv {
            hand,
            layer_move,
            goals,
            goal: Arc::new(LayerGoal::default()),
            desired: layer_move.direction() * FRAC_PI_2,
            hinge,
        }
    }

    pub fn layer_move(&self) -> LayerMove {
        self.layer_move
    }

    /// The angle between the layers, in (-π, π].
    pub fn layer_angle(&self) -> f64 {
        layer_angle(&self.hand, self.hinge)
    }

    /// Sets the layer angle kinematically (for tests and demonstrations).
    pub fn set_layer_angle(&mut self, angle: f64) {
        let data = self.hand.sim.data_mut();
        data.qpos_mut()[self.hinge.qpos] = angle;
        data.qvel_mut()[self.hinge.dof] = 0.0;
        self.hand.sim.forward();
    }

    pub fn set_desired_goal(&mut self, angle: f64) {
        self.desired = angle;
    }

    fn observe(&self) -> Observation {
        observe(&self.hand, self.hinge, self.desired)
    }
}

fn layer_angle(hand: &HandObject, hinge: dexcube_sim::scene::JointAddress) -> f64 {
    wrap_angle(hand.sim.data().qpos()[hinge.qpos])
}

/// The 61 observations and the layer angle, which is also the achieved goal.
fn observe(
    hand: &HandObject,
    hinge: dexcube_sim::scene::JointAddress,
    desired: f64,
) -> Observation {
    let mut observation = hand.base_observation();
    let angle = layer_angle(hand, hinge);
    observation.push(angle);
    Observation {
        observation,
        achieved_goal: vec![angle],
        desired_goal: vec![desired],
    }
}

impl SimulatedEnv for LayerOpEnv {
    fn sim(&self) -> &dexcube_sim::Sim {
        &self.hand.sim
    }

    fn sim_mut(&mut self) -> &mut dexcube_sim::Sim {
        &mut self.hand.sim
    }
}

impl GoalEnv for LayerOpEnv {
    fn spaces(&self) -> Spaces {
        Spaces {
            observation: 62,
            goal: 1,
            action: dexcube_sim::HAND_ACTUATORS,
        }
    }

    fn goal(&self) -> Arc<dyn Goal> {
        self.goal.clone()
    }

    fn reset(&mut self, seed: Option<u64>) -> (Observation, Info) {
        self.hand.seed(seed);
        let (facing, base) = (self.layer_move.facing(), self.layer_move.base_orientation());
        self.hand.place(|rng| {
            let spin = rotation::about(
                facing,
                rng.random_range(-std::f64::consts::PI..std::f64::consts::PI),
            );
            rotation::normalise(&rotation::mul(&spin, &base))
        });
        let size = match self.goals {
            LayerGoals::Training => self.hand.rng.random_range(0.0..=FRAC_PI_2),
            LayerGoals::Evaluation => FRAC_PI_2,
        };
        self.desired = self.layer_move.direction() * size;
        let observation = self.observe();
        let info = self.hand.info(&observation, self.goal.as_ref(), None);
        (observation, info)
    }

    fn step(&mut self, action: &[f64]) -> Transition {
        let (hinge, desired) = (self.hinge, self.desired);
        self.hand.step(action, self.goal.as_ref(), |hand| {
            observe(hand, hinge, desired)
        })
    }
}
