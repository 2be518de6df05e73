//! The two atomic actions as the operator drives them on the physical cube: Stage 1 turns the
//! whole cube so a face is up, Stage 2 turns the top layer U' by a quarter turn. Each is
//! either a trained policy (what the paper evaluates) or a kinematic stand-in that sets the
//! joints directly, for testing the control logic independently of policy quality.

use std::f64::consts::FRAC_PI_2;

use dexcube_cube::Face;
use dexcube_env::random::uniform_rotation;
use dexcube_env::{
    CubeLayer, EPISODE_STEPS, Goal, RotGoal, RotMode, SETTLE_STEPS, base_observation, is_dropped,
    pose_goal, set_down,
};
use dexcube_rl::Policy;
use dexcube_sim::cube::{CubeState, face_toward, turn_face_by};
use dexcube_sim::rotation::{self, Quat};
use dexcube_sim::{HAND_ACTUATORS, Pose, Sim};
use rand_chacha::ChaCha8Rng;

/// The paper's Stage 1 target orientation for each face that can be brought up, in the cube
/// frame (x = R, y = B, z = U): U, R, and the pose the paper names F, which lifts B. Turning
/// B' on top equals F' up to a whole-cube turn, so that pose serves the F moves.
pub fn stage1_target(up: Face) -> Quat {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    match up {
        Face::R => [s, 0.0, -s, 0.0],
        Face::B => [s, s, 0.0, 0.0],
        _ => rotation::IDENTITY,
    }
}

/// What happens to the cube during one atomic action.
pub trait Stage1: Send {
    /// Turns the whole cube so that `target` is its orientation (up to the rotation about
    /// the vertical in axis mode), resting at `position`. At most 100 control steps.
    fn run(&mut self, sim: &mut Sim, position: [f64; 3], target: Quat, watch: Watch) -> StageRun;
}

pub trait Stage2: Send {
    /// Turns the layer on top by U' (+90° about the up direction). At most 100 control steps.
    fn run(&mut self, sim: &mut Sim, watch: Watch) -> StageRun;
}

/// Called after every control step of a stage, e.g. to render a frame.
pub type Watch<'a> = &'a mut dyn FnMut(&mut Sim);

/// How a stage ended.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageRun {
    pub steps: usize,
    pub dropped: bool,
    pub diverged: bool,
}

/// Runs a policy for a whole episode, as its training and `eval-stage` do: the policies learn
/// to reach their goal by the episode's last step and hold it there, so the operator judges
/// the stage at the end, not at the first step the goal is met (a cube caught mid-turn and
/// then let go was dropped half again as often). First the hand opens flat (the model's zero
/// pose) and then takes the neutral action, `SETTLE_STEPS` each, with the cube on its palm:
/// every training episode starts that way, from a hand placed flat and left to settle, while
/// the previous stage leaves the fingers wherever it ended (the paper's "problematic end
/// states"). Going straight to the neutral action from such an end state throws the cube off
/// the palm. These steps count as control steps, not as an action.
fn drive(
    sim: &mut Sim,
    act: impl FnMut(&Sim) -> Vec<f64>,
    resting_z: f64,
    watch: Watch,
) -> StageRun {
    let mut run = StageRun::default();
    let open = sim.scene().open_hand_action().to_vec();
    for relax in [open, vec![0.0; HAND_ACTUATORS]] {
        let hold = |_: &Sim| relax.clone();
        if !advance(sim, hold, SETTLE_STEPS, resting_z, watch, &mut run) {
            return run;
        }
    }
    advance(sim, act, EPISODE_STEPS, resting_z, watch, &mut run);
    run
}

/// `steps` control steps of `act`; false if the cube dropped or the physics blew up (noted in
/// `run`).
fn advance(
    sim: &mut Sim,
    mut act: impl FnMut(&Sim) -> Vec<f64>,
    steps: usize,
    resting_z: f64,
    watch: Watch,
    run: &mut StageRun,
) -> bool {
    for _ in 0..steps {
        let action = act(sim);
        let mut clipped = [0.0; HAND_ACTUATORS];
        for (c, a) in clipped.iter_mut().zip(&action) {
            *c = a.clamp(-1.0, 1.0);
        }
        sim.set_action(&clipped);
        run.steps += 1;
        if sim.step().is_err() {
            run.diverged = true;
            return false;
        }
        watch(sim);
        if is_dropped(sim, resting_z) {
            run.dropped = true;
            return false;
        }
    }
    true
}

/// Stage 1 by a CubeRotEnv policy.
pub struct PolicyStage1 {
    pub policy: Policy,
    pub mode: RotMode,
}

impl Stage1 for PolicyStage1 {
    fn run(&mut self, sim: &mut Sim, position: [f64; 3], target: Quat, watch: Watch) -> StageRun {
        let goal = pose_goal(position, target);
        let policy = &self.policy;
        drive(
            sim,
            |sim| policy.act(&base_observation(sim), &goal),
            position[2],
            watch,
        )
    }
}

/// Stage 2 by a LayerOpEnv U' policy, which sees the cube as LayerOpEnv does on the `cube`
/// scene ([`CubeLayer`]): the layer that stays, and the angle turned since the stage began.
pub struct PolicyStage2 {
    pub policy: Policy,
    pub resting_z: f64,
}

/// The cube-frame face whose outward normal points most nearly up in the world.
pub fn face_up(sim: &Sim) -> Face {
    face_toward(&sim.object_pose().orientation, UP)
}

const UP: [f64; 3] = [0.0, 0.0, 1.0];

impl Stage2 for PolicyStage2 {
    fn run(&mut self, sim: &mut Sim, watch: Watch) -> StageRun {
        let Some(mut view) = CubeLayer::start(sim, UP, rotation::IDENTITY) else {
            return StageRun::default();
        };
        let goal = [FRAC_PI_2];
        let policy = &self.policy;
        drive(
            sim,
            |sim| policy.act(&view.observe(sim), &goal),
            self.resting_z,
            watch,
        )
    }
}

/// A perfect Stage 1: sets the cube's orientation, for testing the logic around it.
pub struct KinematicStage1;

impl Stage1 for KinematicStage1 {
    fn run(&mut self, sim: &mut Sim, position: [f64; 3], target: Quat, watch: Watch) -> StageRun {
        sim.set_object_pose(&Pose {
            position,
            orientation: target,
        });
        sim.forward();
        watch(sim);
        StageRun {
            steps: 1,
            ..StageRun::default()
        }
    }
}

/// A Stage 2 that turns the top layer by a set angle (a perfect U' is +90°), for tests.
pub struct KinematicStage2 {
    pub angle: f64,
}

impl Stage2 for KinematicStage2 {
    fn run(&mut self, sim: &mut Sim, watch: Watch) -> StageRun {
        turn_face_by(sim, Face::U, self.angle);
        sim.forward();
        watch(sim);
        StageRun {
            steps: 1,
            ..StageRun::default()
        }
    }
}

/// Re-seats the cube on the palm at a uniformly random orientation, keeping its layers as
/// they are: the paper's randomisation before Stage 1 is repeated. It is done as a training
/// episode starts: the hand is put back flat, the cube set down near `position` and left to
/// settle under the neutral action, and set down afresh, up to ten times, if it rolls off or
/// lands with a layer knocked out of square (each try starts from the layers as they were).
pub fn randomise_pose(sim: &mut Sim, position: [f64; 3], rng: &mut ChaCha8Rng) {
    let layers = CubeState::read(sim);
    set_down(sim, position[2], |sim| {
        sim.reset_hand();
        if let Some(layers) = &layers {
            layers.restore_layers(sim);
        }
        Pose {
            position,
            orientation: uniform_rotation(rng),
        }
    });
}

/// The rollback's pose check after Stage 1: CubeRotEnv's success test in `mode`, judged on
/// the physical cube's pose.
pub fn pose_reached(mode: RotMode) -> impl Fn(&Sim, [f64; 3], Quat) -> bool {
    move |sim, position, target| {
        let pose = sim.object_pose();
        RotGoal::paper(mode).is_success(
            &pose_goal(pose.position, pose.orientation),
            &pose_goal(position, target),
        )
    }
}
