//! The physical 2x2x2 cube read back from the physics, and turned by hand (kinematically).
//!
//! The cube's frame is its DBL cubelet's: x = R, y = B, z = U, origin at the cube's centre.
//! DBL carries the free joint, and each other cubelet's ball-joint quaternion is its rotation
//! within that frame. Snapping each rotation to the nearest of the cube's 24 rotations says
//! which slot the cubelet is in and how it is twisted, which gives the 24 stickers. What is
//! left over after snapping is the misalignment that the "good state" check bounds.

use std::f64::consts::FRAC_PI_2;

use dexcube_cube::facelet::{CORNER_COLOURS, CORNER_FACELETS, CORNER_NAMES, DBL};
use dexcube_cube::{Face, FaceletError, Facelets, Move};

use crate::rotation::{self, IDENTITY, Quat};
use crate::scene::JointAddress;
use crate::sim::{Pose, Sim};

/// The detent that pulls each cubelet towards the nearest quarter-turn position, as the
/// magnets of a speed cube do: torque `DETENT_STIFFNESS · θ · (1 − θ / DETENT_CAPTURE)` for
/// a misalignment θ below the capture angle, none beyond. Chamfers alone cannot tolerate 5°:
/// with U off by θ, turning R by φ drives the tilted URF|UFL face about 25 mm · θ · φ into
/// UFL, so a 0.2 mm gap allows about 0.5°, and the contact pushes URF and UFL opposite ways
/// about z, giving the U layer no net push back. The detent re-aligns a layer that the hand
/// lets go of within the capture angle, so the next turn goes through, as on a real cube.
pub const DETENT_STIFFNESS: f64 = 0.09;
/// Beyond this misalignment (0.1 rad, 5.7°: the good-state tolerance) the detent lets go.
pub const DETENT_CAPTURE: f64 = ALIGNED_TOLERANCE;

/// Misalignment below which a cube is in a "good state": every cubelet within 0.1 rad of a
/// quarter-turn position, the paper's Stage 2 success threshold.
pub const ALIGNED_TOLERANCE: f64 = 0.1;

/// The physical cube's state, read from a `cube` scene at one instant.
#[derive(Clone, Debug)]
pub struct CubeState {
    pose: Pose,
    /// Each cubelet's rotation within the cube frame, by home slot (DBL's is the identity).
    rotations: [Quat; 8],
    /// Each cubelet's angular velocity in the cube frame, rad/s, by home slot.
    spins: [[f64; 3]; 8],
}

impl CubeState {
    /// Reads the cube; `None` if the simulation is not of the `cube` scene.
    pub fn read(sim: &Sim) -> Option<CubeState> {
        let balls = sim.scene().object().cube_balls()?;
        let mut rotations = [IDENTITY; 8];
        // DBL's own angular velocity (its free joint's, in its frame, which is the cube's);
        // a ball joint's velocity is relative to DBL and in the cubelet's own frame.
        let (_, frame_spin) = sim.object_velocity();
        let mut spins = [frame_spin; 8];
        for (slot, ball) in balls.into_iter().enumerate() {
            rotations[slot] = rotation::normalise(&sim.ball(ball));
            let relative = rotation::rotate(&rotations[slot], sim.ball_velocity(ball));
            spins[slot] = std::array::from_fn(|k| frame_spin[k] + relative[k]);
        }
        Some(CubeState {
            pose: sim.object_pose(),
            rotations,
            spins,
        })
    }

    /// Puts every cubelet back to its rotation in this reading, velocities zeroed, leaving the
    /// cube's pose as it is now: its layers as they were read. Call `Sim::forward` (or step)
    /// after.
    pub fn restore_layers(&self, sim: &mut Sim) {
        if let Some(balls) = sim.scene().object().cube_balls() {
            for (slot, ball) in balls.into_iter().enumerate() {
                sim.set_ball(ball, &self.rotations[slot]);
            }
        }
    }

    /// The cube's centre and its frame's orientation in the world.
    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// The rotation of the cubelet whose home is `slot` (cube crate order), within the cube
    /// frame; DBL's is the identity.
    pub fn cubelet_rotation(&self, slot: usize) -> Quat {
        self.rotations[slot]
    }

    /// The largest angle between a cubelet's rotation and the nearest quarter-turn position.
    pub fn misalignment(&self) -> f64 {
        self.rotations
            .iter()
            .map(|q| rotation::snap_to_cube(q, rotation::cube_group()).1)
            .fold(0.0, f64::max)
    }

    /// The paper's "good state": every layer within `ALIGNED_TOLERANCE` of a quarter turn.
    pub fn is_aligned(&self) -> bool {
        self.misalignment() < ALIGNED_TOLERANCE
    }

    /// The angle in (-π/4, π/4] of the layer on `face` against the opposite layer, about
    /// `face`'s outward normal: positive is counter-clockwise seen from outside that face.
    pub fn layer_angle(&self, face: Face) -> f64 {
        let axis = face_normal(face);
        let (mut near, mut far) = (Vec::new(), Vec::new());
        for (home, q) in self.rotations.iter().enumerate() {
            let (snapped, _) = rotation::snap_to_cube(q, rotation::cube_group());
            let residual = rotation::mul(q, &rotation::conj(&snapped));
            let twist = rotation::twist_about(&residual, axis);
            if in_layer(&snapped, home, axis) {
                near.push(twist);
            } else {
                far.push(twist);
            }
        }
        mean(&near) - mean(&far)
    }

    /// How the layer opposite `face` (the one that stays while `face` turns) moves: its
    /// orientation in the world, as the cube frame would be if that layer were home, and its
    /// angular velocity in the world frame. Both are means over its four cubelets.
    pub fn layer_behind(&self, face: Face) -> (Quat, [f64; 3]) {
        let axis = face_normal(face);
        self.mean_frame_of(|home, snapped| !in_layer(snapped, home, axis))
    }

    /// The cube's orientation in the world as all eight cubelets carry it: the mean of the
    /// frames each would give were it home. On a square cube it is DBL's, the cube frame; on a
    /// cube with a layer or a cubelet out of line it splits the difference, where DBL's frame
    /// follows that one cubelet.
    pub fn mean_frame(&self) -> Quat {
        self.mean_frame_of(|_, _| true).0
    }

    /// The mean over the cubelets `counted` (by home slot and snapped rotation) of the cube
    /// frame each carries, in the world, and of their angular velocities in the world frame.
    fn mean_frame_of(&self, counted: impl Fn(usize, &Quat) -> bool) -> (Quat, [f64; 3]) {
        let (mut sum, mut spin, mut n) = ([0.0; 4], [0.0; 3], 0.0);
        for (home, q) in self.rotations.iter().enumerate() {
            let (snapped, _) = rotation::snap_to_cube(q, rotation::cube_group());
            if !counted(home, &snapped) {
                continue;
            }
            // The cube frame carried by this cubelet: its rotation with its slot taken away.
            // Near 45° cubelets may snap to neighbouring slots, which turns what they carry
            // by a cube rotation; bring each to the first one's before averaging.
            let mut carried = rotation::mul(q, &rotation::conj(&snapped));
            if n > 0.0 {
                let (g, _) = rotation::snap_to_cube(
                    &rotation::mul(&rotation::conj(&carried), &sum),
                    rotation::cube_group(),
                );
                carried = rotation::mul(&carried, &g);
            }
            let reference = if n > 0.0 { sum } else { IDENTITY };
            let sign = carried
                .iter()
                .zip(&reference)
                .map(|(a, b)| a * b)
                .sum::<f64>()
                .signum();
            for (total, c) in sum.iter_mut().zip(carried) {
                *total += sign * c;
            }
            for (total, w) in spin.iter_mut().zip(self.spins[home]) {
                *total += w;
            }
            n += 1.0;
        }
        let orientation = rotation::mul(&self.pose.orientation, &rotation::normalise(&sum));
        let spin = rotation::rotate(&self.pose.orientation, spin.map(|w| w / n));
        (rotation::normalise(&orientation), spin)
    }

    /// The 24 stickers seen in the cube's own frame: DBL is always home, so this is the
    /// solver's normalised view.
    pub fn facelets_in_cube_frame(&self) -> Result<Facelets, FaceletError> {
        self.facelets_seen_from(&IDENTITY)
    }

    /// Whether this cube has a layer turned from the puzzle `start` (its stickers in its own
    /// frame, as [`read_puzzle`] gives them); false if they cannot be read.
    pub fn turned_since(&self, start: &Facelets) -> bool {
        self.facelets_in_cube_frame().is_ok_and(|now| now != *start)
    }

    /// The 24 stickers by the world direction they face (U up, R towards +x, B towards +y),
    /// with the cube's orientation snapped to the nearest axis-aligned one.
    pub fn facelets_in_world(&self) -> Result<Facelets, FaceletError> {
        let (frame, _) = rotation::snap_to_cube(&self.pose.orientation, rotation::cube_group());
        self.facelets_seen_from(&frame)
    }

    fn facelets_seen_from(&self, frame: &Quat) -> Result<Facelets, FaceletError> {
        let mut stickers = ['?'; 24];
        for (home, q) in self.rotations.iter().enumerate() {
            let (snapped, _) = rotation::snap_to_cube(q, rotation::cube_group());
            let g = rotation::mul(frame, &snapped);
            let slot = slot_at(rotation::rotate(&g, slot_centre(home)));
            for k in 0..3 {
                let home_face = Face::ALL[CORNER_FACELETS[home][k] / 4];
                let face = face_at(rotation::rotate(&g, face_normal(home_face)));
                let index = CORNER_FACELETS[slot]
                    .into_iter()
                    .find(|&i| i / 4 == face as usize)
                    .expect("a rotated corner sticker faces one of its slot's faces");
                stickers[index] = CORNER_COLOURS[home][k].letter();
            }
        }
        Facelets::parse(&stickers.iter().collect::<String>())
    }
}

/// The physical cube's puzzle in `sim`: its stickers in its own frame, which a turn of the
/// whole cube leaves as they are and a turn of any layer changes. `None` off the cube scene,
/// or with a cubelet too far between positions to read.
pub fn read_puzzle(sim: &Sim) -> Option<Facelets> {
    CubeState::read(sim)?.facelets_in_cube_frame().ok()
}

/// Whether the cube in `sim` has a layer turned from the puzzle `start` (false if either
/// cannot be read): what a re-posing of the whole cube, Stage 1, must never do.
pub fn turned_since(start: Option<&Facelets>, sim: &Sim) -> bool {
    start.is_some_and(|start| CubeState::read(sim).is_some_and(|cube| cube.turned_since(start)))
}

/// Turns one face of the cube in the physics by setting joint positions, as a perfect hand
/// would; velocities of the moved joints are zeroed. Faces are named as seen in the world
/// (U is the layer facing up, R the one facing +x, B the one facing +y), like
/// `facelets_in_world`. Call `Sim::forward` (or step) after. Returns `false` if the
/// simulation is not of the `cube` scene.
pub fn turn_face(sim: &mut Sim, m: Move) -> bool {
    turn_face_by(sim, m.face, -(m.quarters as f64) * FRAC_PI_2)
}

/// Turns the layer facing `face` in the world by `angle` radians about its outward normal
/// (counter-clockwise seen from outside is positive), kinematically.
pub fn turn_face_by(sim: &mut Sim, face: Face, angle: f64) -> bool {
    let Some(balls) = sim.scene().object().cube_balls() else {
        return false;
    };
    let Some(state) = CubeState::read(sim) else {
        return false;
    };
    // The same face in the cube's own frame: the one pointing most nearly along the world
    // face's normal, as `face_toward` names it for Stage 2 (a cube tilted near 45° can snap
    // to a frame with another face up).
    let face = face_toward(&state.pose.orientation, face_normal(face));
    let turn = rotation::about(face_normal(face), angle);
    let in_layer: Vec<bool> = state
        .rotations
        .iter()
        .enumerate()
        .map(|(home, q)| {
            in_layer(
                &rotation::snap_to_cube(q, rotation::cube_group()).0,
                home,
                face_normal(face),
            )
        })
        .collect();
    if in_layer[DBL] {
        // DBL's layer turns: turn the cube frame with it, and the other layer back.
        let mut pose = state.pose;
        pose.orientation = rotation::normalise(&rotation::mul(&pose.orientation, &turn));
        sim.set_object_pose(&pose);
        let back = rotation::conj(&turn);
        for slot in (0..7).filter(|&s| !in_layer[s]) {
            sim.set_ball(
                balls[slot],
                &rotation::normalise(&rotation::mul(&back, &state.rotations[slot])),
            );
        }
    } else {
        for slot in (0..7).filter(|&s| in_layer[s]) {
            sim.set_ball(
                balls[slot],
                &rotation::normalise(&rotation::mul(&turn, &state.rotations[slot])),
            );
        }
    }
    true
}

/// Sets every cubelet to its nearest quarter-turn position, as a hand working the layers
/// until they click would; velocities of the cubelets are zeroed. False if not a cube scene.
pub fn snap_layers(sim: &mut Sim) -> bool {
    let Some(balls) = sim.scene().object().cube_balls() else {
        return false;
    };
    for ball in balls {
        let (snapped, _) = rotation::snap_to_cube(
            &rotation::normalise(&sim.ball(ball)),
            rotation::cube_group(),
        );
        sim.set_ball(ball, &snapped);
    }
    sim.forward();
    true
}

/// Sets each cubelet's detent torque as an applied joint force, for the next physics step.
pub(crate) fn apply_detent(sim: &mut Sim, balls: &[JointAddress; 7]) {
    for &ball in balls {
        let q = rotation::normalise(&sim.ball(ball));
        let (snapped, angle) = rotation::snap_to_cube(&q, rotation::cube_group());
        let torque = if !(1e-9..DETENT_CAPTURE).contains(&angle) {
            [0.0; 3]
        } else {
            // The residual rotation's axis, in the cubelet's own frame (ball joints' velocity
            // coordinates), pushed back with the detent's profile.
            let mut residual = rotation::mul(&rotation::conj(&snapped), &q);
            if residual[0] < 0.0 {
                residual = residual.map(|x| -x);
            }
            let norm = (residual[1].powi(2) + residual[2].powi(2) + residual[3].powi(2)).sqrt();
            let size = DETENT_STIFFNESS * angle * (1.0 - angle / DETENT_CAPTURE) / norm;
            [
                -residual[1] * size,
                -residual[2] * size,
                -residual[3] * size,
            ]
        };
        sim.data_mut().qfrc_applied_mut()[ball.dof..ball.dof + 3].copy_from_slice(&torque);
    }
}

/// The outward normal of a face in the cube frame (x = R, y = B, z = U).
pub fn face_normal(face: Face) -> [f64; 3] {
    match face {
        Face::U => [0.0, 0.0, 1.0],
        Face::D => [0.0, 0.0, -1.0],
        Face::R => [1.0, 0.0, 0.0],
        Face::L => [-1.0, 0.0, 0.0],
        Face::B => [0.0, 1.0, 0.0],
        Face::F => [0.0, -1.0, 0.0],
    }
}

/// How far, in degrees from 0 to 45, a cube with `orientation` lying on one face is turned
/// about the vertical from square to the world's x and y axes (the hand's, on the palm): the
/// side face whose normal lies most nearly level gives the yaw, a cube's sides repeating every
/// 90 degrees. Any of the cube's symmetries applied to `orientation` gives the same yaw.
pub fn yaw_from_square(orientation: &Quat) -> f64 {
    let side = [Face::R, Face::B, Face::U]
        .map(|face| rotation::rotate(orientation, face_normal(face)))
        .into_iter()
        .min_by(|a, b| a[2].abs().total_cmp(&b[2].abs()))
        .expect("three faces");
    let yaw = side[1].atan2(side[0]).to_degrees().rem_euclid(90.0);
    yaw.min(90.0 - yaw)
}

/// The direction from the cube's centre to a corner slot (components ±1).
fn slot_centre(slot: usize) -> [f64; 3] {
    CORNER_NAMES[slot].chars().fold([0.0; 3], |acc, letter| {
        let n = face_normal(Face::from_letter(letter).expect("corner names are face letters"));
        [acc[0] + n[0], acc[1] + n[1], acc[2] + n[2]]
    })
}

/// Whether the cubelet from `home`, now at the slot `snapped` takes it to, is in the layer
/// facing `axis` (cube frame).
fn in_layer(snapped: &Quat, home: usize, axis: [f64; 3]) -> bool {
    dot(rotation::rotate(snapped, slot_centre(home)), axis) > 0.0
}

/// The slot whose direction is nearest `v`.
fn slot_at(v: [f64; 3]) -> usize {
    (0..8)
        .max_by(|&a, &b| dot(slot_centre(a), v).total_cmp(&dot(slot_centre(b), v)))
        .unwrap_or(0)
}

/// The cube-frame face that points most nearly along the world `direction`, for a cube
/// whose frame has `orientation`.
pub fn face_toward(orientation: &Quat, direction: [f64; 3]) -> Face {
    face_at(rotation::rotate(&rotation::conj(orientation), direction))
}

/// The face whose normal is nearest `v`.
fn face_at(v: [f64; 3]) -> Face {
    Face::ALL
        .into_iter()
        .max_by(|&a, &b| dot(face_normal(a), v).total_cmp(&dot(face_normal(b), v)))
        .unwrap_or(Face::U)
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn mean(xs: &[f64]) -> f64 {
    if xs.is_empty() {
        0.0
    } else {
        xs.iter().sum::<f64>() / xs.len() as f64
    }
}
