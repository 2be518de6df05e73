//! One running simulation of a scene: its own `MjData` over the scene's shared model, a
//! control step of 20 physics substeps, blow-up detection, the state every environment
//! reads (hand joints, the object's pose and velocities, the hand's grip on it), and the
//! scene's physics scaled for one episode ([`PhysicsScales`]).

use std::sync::Arc;

use mujoco_rs::mujoco_c::mjtWarning;
use mujoco_rs::prelude::*;

use crate::error::SimError;
use crate::rotation::Quat;
use crate::scene::{GRIP_PARTS, GeomOwner, HAND_ACTUATORS, HAND_JOINTS, JointAddress, Scene};

/// Physics substeps of 0.002 s per control step, as in Gymnasium-Robotics' hand envs.
pub const SUBSTEPS: usize = 20;

/// MuJoCo's warnings for a state it had to reset, with what each means.
const BAD_STATE_WARNINGS: [(mjtWarning, &str); 3] = [
    (
        mjtWarning::mjWARN_BADQPOS,
        "a bad joint position (mjWARN_BADQPOS)",
    ),
    (
        mjtWarning::mjWARN_BADQVEL,
        "a bad joint velocity (mjWARN_BADQVEL)",
    ),
    (
        mjtWarning::mjWARN_BADQACC,
        "a bad acceleration (mjWARN_BADQACC)",
    ),
];

/// What a recorded physics state holds: MuJoCo's integration state (time, joint positions
/// and velocities, activations, the solver's warm start, controls, mocap poses, equality
/// switches) less the applied forces, which the cube's detent sets afresh before every
/// substep. Restoring it continues the simulation exactly as it would have gone on.
pub(crate) const PHYSICS_STATE: u32 = MjtState::mjSTATE_TIME as u32
    | MjtState::mjSTATE_QPOS as u32
    | MjtState::mjSTATE_QVEL as u32
    | MjtState::mjSTATE_ACT as u32
    | MjtState::mjSTATE_WARMSTART as u32
    | MjtState::mjSTATE_CTRL as u32
    | MjtState::mjSTATE_EQ_ACTIVE as u32
    | MjtState::mjSTATE_MOCAP_POS as u32
    | MjtState::mjSTATE_MOCAP_QUAT as u32;

/// A position and orientation in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub position: [f64; 3],
    pub orientation: Quat,
}

/// Multipliers on a scene's physics, for training under varied physics (domain
/// randomisation, as OpenAI et al. 2019 trained their Shadow Hand): every geom's friction
/// (sliding, torsional and rolling), the object's mass and inertia, and every joint's damping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicsScales {
    pub friction: f64,
    pub object_mass: f64,
    pub damping: f64,
}

impl PhysicsScales {
    /// The scene's own physics, as its MJCF gives it.
    pub const NOMINAL: PhysicsScales = PhysicsScales {
        friction: 1.0,
        object_mass: 1.0,
        damping: 1.0,
    };
}

pub struct Sim {
    scene: Arc<Scene>,
    data: MjData<Arc<MjModel>>,
    control_steps: u64,
    physics_time: std::time::Duration,
}

impl Sim {
    pub fn new(scene: Arc<Scene>) -> Sim {
        let data = MjData::new(scene.model().clone());
        let mut sim = Sim {
            scene,
            data,
            control_steps: 0,
            physics_time: std::time::Duration::ZERO,
        };
        sim.reset();
        sim
    }

    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    /// The raw MuJoCo state, for what this wrapper does not cover.
    pub fn data(&self) -> &MjData<Arc<MjModel>> {
        &self.data
    }

    pub fn data_mut(&mut self) -> &mut MjData<Arc<MjModel>> {
        &mut self.data
    }

    /// Runs this simulation on the scene's physics scaled by `scales` until the next call,
    /// resets included; [`PhysicsScales::NOMINAL`] puts the scene's own physics back. The
    /// state is kept as it is.
    pub fn set_physics_scales(&mut self, scales: PhysicsScales) {
        let model = if scales == PhysicsScales::NOMINAL {
            self.scene.model().clone()
        } else {
            let mut model = MjModel::clone(self.scene.model());
            for friction in model.geom_friction_mut() {
                friction.iter_mut().for_each(|f| *f *= scales.friction);
            }
            for &body in self.scene.object_bodies() {
                model.body_mass_mut()[body] *= scales.object_mass;
                model.body_inertia_mut()[body]
                    .iter_mut()
                    .for_each(|i| *i *= scales.object_mass);
            }
            model
                .dof_damping_mut()
                .iter_mut()
                .for_each(|d| *d *= scales.damping);
            // What MuJoCo derives from the masses (subtree masses, the inverse weights that
            // scale constraint softness) follows them.
            MjData::new(&mut model).set_const();
            Arc::new(model)
        };
        self.data.swap_model(model);
    }

    /// Back to the model's initial state (the hand's joints at zero, the object on the palm).
    pub fn reset(&mut self) {
        self.data.reset();
        self.data.forward();
    }

    /// Puts the hand back at its initial pose (every joint at zero: flat and open), at rest,
    /// leaving the object as it is.
    pub fn reset_hand(&mut self) {
        for joint in *self.scene.hand_joints() {
            self.data.qpos_mut()[joint.qpos] = 0.0;
            self.data.qvel_mut()[joint.dof] = 0.0;
        }
    }

    /// Control steps run since this simulation was made, resets and all.
    pub fn control_steps(&self) -> u64 {
        self.control_steps
    }

    /// Wall time spent inside `step` since this simulation was made: what a caller's own
    /// overhead is measured against.
    pub fn physics_time(&self) -> std::time::Duration {
        self.physics_time
    }

    /// Simulated time in seconds.
    pub fn time(&self) -> f64 {
        self.data.ffi().time
    }

    /// Sets the hand's actuator targets from an action in [-1, 1]^20.
    pub fn set_action(&mut self, action: &[f64; HAND_ACTUATORS]) {
        self.scene
            .action_to_ctrl(action, &mut self.data.ctrl_mut()[..HAND_ACTUATORS]);
    }

    /// The hand's current action: the one whose targets the actuators now hold.
    pub fn action(&self) -> [f64; HAND_ACTUATORS] {
        self.scene
            .ctrl_to_action(&self.data.ctrl()[..HAND_ACTUATORS])
    }

    /// One control step: `SUBSTEPS` physics steps. Fails if the state blew up, in which case
    /// the caller should `reset`.
    pub fn step(&mut self) -> Result<(), SimError> {
        self.step_substeps(SUBSTEPS)
    }

    /// One control step of `substeps` physics steps, for a control rate other than the
    /// paper's; fails as [`Sim::step`] does.
    pub fn step_substeps(&mut self, substeps: usize) -> Result<(), SimError> {
        let start = std::time::Instant::now();
        let before = self.bad_state_warnings();
        self.control_steps += 1;
        // Only the physical cube has cubelets to hold in line.
        let cubelets = self.scene.object().cube_balls();
        for _ in 0..substeps {
            if let Some(balls) = &cubelets {
                crate::cube::apply_detent(self, balls);
            }
            self.data.step();
        }
        let checked = self.check_finite(before);
        self.physics_time += start.elapsed();
        checked
    }

    /// The physics state, to restore later into this scene's simulations
    /// ([`Sim::restore_physics_state`]): e.g. where an operator's stage began.
    pub fn physics_state(&self) -> Vec<f64> {
        self.data.state(PHYSICS_STATE).into_vec()
    }

    /// Puts the simulation back in a state taken by [`Sim::physics_state`] from this scene;
    /// fails, leaving it as it was, if the state has the wrong size for it.
    pub fn restore_physics_state(&mut self, state: &[f64]) -> Result<(), SimError> {
        let expected = self.scene.physics_state_size();
        if state.len() != expected {
            return Err(SimError::BadState {
                message: format!(
                    "{} numbers, where this scene's state has {expected}",
                    state.len()
                ),
            });
        }
        self.data
            .set_state(state, PHYSICS_STATE)
            .map_err(|e| SimError::BadState {
                message: e.to_string(),
            })?;
        self.data.forward();
        Ok(())
    }

    /// Recomputes positions, contacts and the rest after the state was set by hand.
    pub fn forward(&mut self) {
        self.data.forward();
    }

    /// How often MuJoCo has found a bad position, velocity or acceleration (and reset the
    /// state because of it), by kind.
    fn bad_state_warnings(&self) -> [i32; 3] {
        let warnings = self.data.warning();
        BAD_STATE_WARNINGS.map(|(w, _)| warnings[w as usize].number)
    }

    fn check_finite(&mut self, before: [i32; 3]) -> Result<(), SimError> {
        let after = self.bad_state_warnings();
        if let Some(k) = (0..3).find(|&k| after[k] > before[k]) {
            let what = format!(
                "MuJoCo found {} and reset the state",
                BAD_STATE_WARNINGS[k].1
            );
            return Err(SimError::Diverged {
                time: self.time(),
                what,
            });
        }
        if !self
            .data
            .qpos()
            .iter()
            .chain(self.data.qvel())
            .all(|x| x.is_finite())
        {
            let what = "NaN or infinite joint positions or velocities".to_string();
            return Err(SimError::Diverged {
                time: self.time(),
                what,
            });
        }
        Ok(())
    }

    /// The hand's 24 joint angles (radians).
    pub fn hand_angles(&self) -> [f64; HAND_JOINTS] {
        self.scene.hand_joints().map(|j| self.data.qpos()[j.qpos])
    }

    /// The hand's 24 joint velocities (rad/s).
    pub fn hand_velocities(&self) -> [f64; HAND_JOINTS] {
        self.scene.hand_joints().map(|j| self.data.qvel()[j.dof])
    }

    /// The pose of the object's free joint: the rigid cube's, the block's bottom layer's, or
    /// the physical cube's (its centre, and DBL's orientation, which is the cube's frame).
    pub fn object_pose(&self) -> Pose {
        free_pose(self.data.qpos(), self.scene.object().free())
    }

    /// Places the object's free joint, with zero velocity.
    pub fn set_object_pose(&mut self, pose: &Pose) {
        let free = self.scene.object().free();
        let qpos = self.data.qpos_mut();
        qpos[free.qpos..free.qpos + 3].copy_from_slice(&pose.position);
        qpos[free.qpos + 3..free.qpos + 7].copy_from_slice(&pose.orientation);
        self.data.qvel_mut()[free.dof..free.dof + 6].fill(0.0);
    }

    /// The object's linear velocity (world frame, m/s) and angular velocity (rad/s, in the
    /// object's frame, as MuJoCo stores a free joint's rotation velocity).
    pub fn object_velocity(&self) -> ([f64; 3], [f64; 3]) {
        let dof = self.scene.object().free().dof;
        let v = &self.data.qvel()[dof..dof + 6];
        ([v[0], v[1], v[2]], [v[3], v[4], v[5]])
    }

    /// The hand's grip on the object: the normal force (N) with which each of the hand's
    /// [`GRIP_PARTS`] presses on it, summed over their contacts, as the constraint solver
    /// found them in the last physics substep (zero where a part does not touch it).
    pub fn grip(&self) -> [f64; GRIP_PARTS.len()] {
        let owners = self.scene.geom_owners();
        let owner = |geom: i32| usize::try_from(geom).map_or(GeomOwner::Other, |g| owners[g]);
        let mut grip = [0.0; GRIP_PARTS.len()];
        for (id, contact) in self.data.contact().iter().enumerate() {
            if contact.efc_address < 0 {
                continue;
            }
            let part = match (owner(contact.geom[0]), owner(contact.geom[1])) {
                (GeomOwner::Hand(part), GeomOwner::Object)
                | (GeomOwner::Object, GeomOwner::Hand(part)) => part,
                _ => continue,
            };
            grip[part] += self.data.contact_force(id)[0];
        }
        grip
    }

    /// A joint's quaternion coordinates (a ball or free joint's orientation part).
    pub(crate) fn ball(&self, joint: JointAddress) -> Quat {
        let q = &self.data.qpos()[joint.qpos..joint.qpos + 4];
        [q[0], q[1], q[2], q[3]]
    }

    /// A ball joint's angular velocity, in its child body's frame.
    pub(crate) fn ball_velocity(&self, joint: JointAddress) -> [f64; 3] {
        let v = &self.data.qvel()[joint.dof..joint.dof + 3];
        [v[0], v[1], v[2]]
    }

    pub(crate) fn set_ball(&mut self, joint: JointAddress, q: &Quat) {
        self.data.qpos_mut()[joint.qpos..joint.qpos + 4].copy_from_slice(q);
        self.data.qvel_mut()[joint.dof..joint.dof + 3].fill(0.0);
    }
}

fn free_pose(qpos: &[f64], free: JointAddress) -> Pose {
    let q = &qpos[free.qpos..free.qpos + 7];
    Pose {
        position: [q[0], q[1], q[2]],
        orientation: [q[3], q[4], q[5], q[6]],
    }
}
