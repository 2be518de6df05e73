//! The three scenes, loaded from `assets/`, with the addresses of what dexcube reads and
//! drives in each: the hand's 24 joints and 20 actuators, and the object's joints.
//!
//! - `rot`: the hand and a rigid 5 cm cube, with a ghost target (CubeRotEnv).
//! - `layer`: the hand and a two-layer block whose layers are joined by a hinge (LayerOpEnv).
//! - `cube`: the hand and a physical 2x2x2 cube (the operator and the evaluation).

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::MjtObjBase;

use crate::error::SimError;

/// The MuJoCo version mujoco-rs 7.0.0 is built against.
pub const MUJOCO_VERSION: &str = "3.17.0";

/// Number of hand joints (hinges) and of its position actuators.
pub const HAND_JOINTS: usize = 24;
pub const HAND_ACTUATORS: usize = 20;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SceneKind {
    Rot,
    Layer,
    Cube,
}

impl SceneKind {
    pub const ALL: [SceneKind; 3] = [SceneKind::Rot, SceneKind::Layer, SceneKind::Cube];

    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Rot => "rot",
            SceneKind::Layer => "layer",
            SceneKind::Cube => "cube",
        }
    }

    /// The scene file under an assets folder.
    pub fn path_in(self, assets: &Path) -> PathBuf {
        assets.join(self.name()).join("scene.xml")
    }
}

impl fmt::Display for SceneKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The assets folder: `DEXCUBE_ASSETS` if set, else the repository's `assets/`.
pub fn assets_dir() -> PathBuf {
    std::env::var_os("DEXCUBE_ASSETS")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets"))
}

/// Addresses in `qpos` / `qvel` of the object's joints, by scene.
#[derive(Clone, Debug)]
pub enum ObjectJoints {
    /// The rigid cube's free joint, and the ghost target's mocap index.
    Rot {
        free: JointAddress,
        target_mocap: usize,
    },
    /// The block's free joint and the hinge between its layers.
    Layer {
        free: JointAddress,
        hinge: JointAddress,
    },
    /// DBL's free joint, and the ball joints of the other seven cubelets in the cube crate's
    /// slot order (URF, UFL, ULB, UBR, DFR, DLF, DRB).
    Cube {
        free: JointAddress,
        balls: [JointAddress; 7],
    },
}

impl ObjectJoints {
    /// The ball joints of the physical cube's seven moving cubelets; `None` in other scenes.
    pub fn cube_balls(&self) -> Option<[JointAddress; 7]> {
        match self {
            ObjectJoints::Cube { balls, .. } => Some(*balls),
            _ => None,
        }
    }

    /// The free joint that places the object in the world.
    pub fn free(&self) -> JointAddress {
        match self {
            ObjectJoints::Rot { free, .. }
            | ObjectJoints::Layer { free, .. }
            | ObjectJoints::Cube { free, .. } => *free,
        }
    }
}

/// Where a joint's coordinates start in `qpos` and in `qvel`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JointAddress {
    pub qpos: usize,
    pub dof: usize,
}

/// The parts of the hand whose grip on the object [`crate::Sim::grip`] reports, each named by
/// the body its subtree starts at: the thumb, the four fingers (the little finger from its
/// metacarpal), and the palm less the fingers.
pub const GRIP_PARTS: [&str; 6] = [
    "robot0:thbase",
    "robot0:ffknuckle",
    "robot0:mfknuckle",
    "robot0:rfknuckle",
    "robot0:lfmetacarpal",
    "robot0:palm",
];

/// What a body, and so each of its geoms, belongs to, for reading the hand's grip from the
/// contacts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum GeomOwner {
    /// The hand, in the part at this index of [`GRIP_PARTS`].
    Hand(usize),
    /// The object on the palm (any of its bodies).
    Object,
    /// Anything else (the forearm, the floor, the ghost target).
    Other,
}

/// A compiled scene, shared by every simulation of it.
pub struct Scene {
    kind: SceneKind,
    path: PathBuf,
    model: Arc<MjModel>,
    hand_joints: [JointAddress; HAND_JOINTS],
    ctrl_centre: [f64; HAND_ACTUATORS],
    ctrl_half_range: [f64; HAND_ACTUATORS],
    object: ObjectJoints,
    geom_owners: Vec<GeomOwner>,
    object_bodies: Vec<usize>,
}

impl Scene {
    /// Loads a scene from the assets folder.
    pub fn load(kind: SceneKind) -> Result<Arc<Scene>, SimError> {
        Scene::load_from(kind, &assets_dir())
    }

    /// Loads a scene from a given assets folder, checking the library version and the files
    /// first so that every failure names its cause.
    pub fn load_from(kind: SceneKind, assets: &Path) -> Result<Arc<Scene>, SimError> {
        let found = mujoco_rs::mujoco_version();
        if found != MUJOCO_VERSION {
            return Err(SimError::VersionMismatch {
                found: found.to_string(),
                expected: MUJOCO_VERSION,
            });
        }
        let path = kind.path_in(assets);
        for needed in [path.clone(), assets.join("shadow_hand/hand/robot.xml")] {
            if !needed.is_file() {
                return Err(SimError::MissingAsset { path: needed });
            }
        }
        let model = MjModel::from_xml(&path).map_err(|e| SimError::Load {
            path: path.clone(),
            message: e.to_string().trim().to_string(),
        })?;
        let lookup = Lookup {
            model: &model,
            path: &path,
        };
        let hand_joints = collect_array(HAND_JOINT_NAMES.map(|n| lookup.joint(n)))?;
        let mut ctrl_centre = [0.0; HAND_ACTUATORS];
        let mut ctrl_half_range = [0.0; HAND_ACTUATORS];
        for (i, name) in HAND_ACTUATOR_NAMES.iter().enumerate() {
            let id = lookup.id(MjtObjBase::mjOBJ_ACTUATOR, "actuator", name)?;
            let [low, high] = model.actuator_ctrlrange()[id];
            ctrl_centre[i] = (low + high) / 2.0;
            ctrl_half_range[i] = (high - low) / 2.0;
        }
        let object = match kind {
            SceneKind::Rot => ObjectJoints::Rot {
                free: lookup.joint("object:joint")?,
                target_mocap: {
                    let body = lookup.id(MjtObjBase::mjOBJ_BODY, "body", "target")?;
                    model.body_mocapid()[body] as usize
                },
            },
            SceneKind::Layer => ObjectJoints::Layer {
                free: lookup.joint("object:joint")?,
                hinge: lookup.joint("object:layer")?,
            },
            SceneKind::Cube => ObjectJoints::Cube {
                free: lookup.joint("cube:joint")?,
                balls: collect_array(
                    ["URF", "UFL", "ULB", "UBR", "DFR", "DLF", "DRB"]
                        .map(|c| lookup.joint(&format!("cubelet:{c}"))),
                )?,
            },
        };
        let grip_parts = GRIP_PARTS
            .iter()
            .map(|name| lookup.id(MjtObjBase::mjOBJ_BODY, "body", name))
            .collect::<Result<Vec<_>, _>>()?;
        let object_body = model.dof_bodyid()[object.free().dof] as usize;
        let body_owners = body_owners(&model, object_body, &grip_parts);
        let geom_owners = model
            .geom_bodyid()
            .iter()
            .map(|&body| body_owners[body as usize])
            .collect();
        let object_bodies = (0..body_owners.len())
            .filter(|&body| body_owners[body] == GeomOwner::Object)
            .collect();
        Ok(Arc::new(Scene {
            kind,
            path,
            model: Arc::new(model),
            hand_joints,
            ctrl_centre,
            ctrl_half_range,
            object,
            geom_owners,
            object_bodies,
        }))
    }

    /// What each geom belongs to, by geom id.
    pub(crate) fn geom_owners(&self) -> &[GeomOwner] {
        &self.geom_owners
    }

    /// The object's bodies (the cube and its cubelets), by body id.
    pub(crate) fn object_bodies(&self) -> &[usize] {
        &self.object_bodies
    }

    pub fn kind(&self) -> SceneKind {
        self.kind
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn model(&self) -> &Arc<MjModel> {
        &self.model
    }

    /// How many numbers a physics state of this scene has ([`crate::Sim::physics_state`]).
    pub fn physics_state_size(&self) -> usize {
        self.model.state_size(crate::sim::PHYSICS_STATE)
    }

    /// The hand's 24 joints, wrist first, in Gymnasium-Robotics' order.
    pub fn hand_joints(&self) -> &[JointAddress; HAND_JOINTS] {
        &self.hand_joints
    }

    pub fn object(&self) -> &ObjectJoints {
        &self.object
    }

    /// The actuator targets for an action in [-1, 1]^20: each maps linearly onto its
    /// actuator's control range, as absolute joint targets (Gymnasium-Robotics' default).
    pub fn action_to_ctrl(&self, action: &[f64], ctrl: &mut [f64]) {
        for i in 0..HAND_ACTUATORS {
            let a = action[i].clamp(-1.0, 1.0);
            ctrl[i] = self.ctrl_centre[i] + a * self.ctrl_half_range[i];
        }
    }

    /// The action whose targets are `ctrl` (the inverse of `action_to_ctrl` within range).
    pub fn ctrl_to_action(&self, ctrl: &[f64]) -> [f64; HAND_ACTUATORS] {
        std::array::from_fn(|i| {
            ((ctrl[i] - self.ctrl_centre[i]) / self.ctrl_half_range[i]).clamp(-1.0, 1.0)
        })
    }

    /// The action whose targets are the model's zero pose (the open, flat hand every
    /// episode starts from), clamped into the actuators' ranges.
    pub fn open_hand_action(&self) -> [f64; HAND_ACTUATORS] {
        std::array::from_fn(|i| (-self.ctrl_centre[i] / self.ctrl_half_range[i]).clamp(-1.0, 1.0))
    }
}

/// Name look-ups that fail with the scene's path in the message.
struct Lookup<'a> {
    model: &'a MjModel,
    path: &'a Path,
}

impl Lookup<'_> {
    fn id(&self, kind: MjtObjBase, what: &'static str, name: &str) -> Result<usize, SimError> {
        self.model
            .name_to_id(kind, name)
            .ok_or_else(|| SimError::MissingElement {
                path: self.path.to_path_buf(),
                kind: what,
                name: name.to_string(),
            })
    }

    fn joint(&self, name: &str) -> Result<JointAddress, SimError> {
        let id = self.id(MjtObjBase::mjOBJ_JOINT, "joint", name)?;
        Ok(JointAddress {
            qpos: self.model.jnt_qposadr()[id] as usize,
            dof: self.model.jnt_dofadr()[id] as usize,
        })
    }
}

/// What each body belongs to, by body id: `object_body` and the bodies below it are the
/// object; a body in `grip_parts` starts that hand part, and the bodies below it belong to the
/// nearest such start above them (the palm holds the fingers' roots); the rest are other.
/// MuJoCo numbers a parent before its children, so one pass in order suffices.
fn body_owners(model: &MjModel, object_body: usize, grip_parts: &[usize]) -> Vec<GeomOwner> {
    let parents = model.body_parentid();
    let mut owners = Vec::with_capacity(parents.len());
    for body in 0..parents.len() {
        let owner = if body == object_body {
            GeomOwner::Object
        } else if let Some(part) = grip_parts.iter().position(|&start| start == body) {
            GeomOwner::Hand(part)
        } else if body == 0 {
            GeomOwner::Other
        } else {
            owners[parents[body] as usize]
        };
        owners.push(owner);
    }
    owners
}

fn collect_array<const N: usize>(
    items: [Result<JointAddress, SimError>; N],
) -> Result<[JointAddress; N], SimError> {
    let mut out = [JointAddress { qpos: 0, dof: 0 }; N];
    for (slot, item) in out.iter_mut().zip(items) {
        *slot = item?;
    }
    Ok(out)
}

/// The hand's joints in Gymnasium-Robotics' order.
const HAND_JOINT_NAMES: [&str; HAND_JOINTS] = [
    "robot0:WRJ1",
    "robot0:WRJ0",
    "robot0:FFJ3",
    "robot0:FFJ2",
    "robot0:FFJ1",
    "robot0:FFJ0",
    "robot0:MFJ3",
    "robot0:MFJ2",
    "robot0:MFJ1",
    "robot0:MFJ0",
    "robot0:RFJ3",
    "robot0:RFJ2",
    "robot0:RFJ1",
    "robot0:RFJ0",
    "robot0:LFJ4",
    "robot0:LFJ3",
    "robot0:LFJ2",
    "robot0:LFJ1",
    "robot0:LFJ0",
    "robot0:THJ4",
    "robot0:THJ3",
    "robot0:THJ2",
    "robot0:THJ1",
    "robot0:THJ0",
];

/// The hand's position actuators in Gymnasium-Robotics' order (the distal joints J0 of the
/// four fingers follow J1 through tendons).
const HAND_ACTUATOR_NAMES: [&str; HAND_ACTUATORS] = [
    "robot0:A_WRJ1",
    "robot0:A_WRJ0",
    "robot0:A_FFJ3",
    "robot0:A_FFJ2",
    "robot0:A_FFJ1",
    "robot0:A_MFJ3",
    "robot0:A_MFJ2",
    "robot0:A_MFJ1",
    "robot0:A_RFJ3",
    "robot0:A_RFJ2",
    "robot0:A_RFJ1",
    "robot0:A_LFJ4",
    "robot0:A_LFJ3",
    "robot0:A_LFJ2",
    "robot0:A_LFJ1",
    "robot0:A_THJ4",
    "robot0:A_THJ3",
    "robot0:A_THJ2",
    "robot0:A_THJ1",
    "robot0:A_THJ0",
];
