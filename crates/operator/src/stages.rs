//! The two atomic actions as the operator drives them on the physical cube: Stage 1 turns the
//! whole cube so a face is up, Stage 2 turns the top layer U' by a quarter turn. Each is
//! either a trained policy (what the paper evaluates) or a kinematic stand-in that sets the
//! joints directly, for testing the control logic independently of policy quality.

use std::f64::consts::FRAC_PI_2;
use std::path::Path;

use dexcube_cube::Face;
use dexcube_env::random::uniform_rotation;
use dexcube_env::{
    ControlRate, CubeLayer, CubeRotEnv, Goal, LayerGoal, RecordedStart, RotGoal, RotMode,
    SETTLE_STEPS, View, achieved_goal, cube_misalignment, is_dropped, pose_goal, rot_observation,
    set_down,
};
use dexcube_rl::Policy;
use dexcube_rl::checkpoint::CheckpointError;
use dexcube_sim::cube::{CubeState, face_toward, turn_face_by};
use dexcube_sim::rotation::{self, Quat};
use dexcube_sim::{HAND_ACTUATORS, Pose, SUBSTEPS, Sim};
use rand_chacha::ChaCha8Rng;

/// The faces Stage 1 brings up, one per target pose: U, R and B (which serves the F moves).
pub const STAGE1_FACES: [Face; 3] = [Face::U, Face::R, Face::B];

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

/// How the operator runs the policies on the physical cube, beyond the policies themselves.
/// The paper's operator (`Driving::default()`) opens the hand at once and runs each stage for
/// the policy's whole episode; the operator planning for the hand does neither
/// (`Driving::FOR_HAND`): both were measured in the operator (`results/TRAINING.md`,
/// session 6).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Driving {
    /// Open the hand from where the last stage left it by moving its targets to the flat
    /// hand step by step over the first settling steps, rather than at once.
    pub gradual_opening: bool,
    /// End Stage 1 once its pose test has passed for this many control steps running,
    /// rather than after the policy's whole episode.
    pub stage1_held_steps: Option<usize>,
    /// During Stage 1, let the cube steady itself whenever it strays from its resting point.
    pub stage1_steadying: Option<Steadying>,
    /// Run Stage 1's policy at this control rate rather than at the one it was trained at.
    pub stage1_control_rate: Option<ControlRate>,
    /// Run Stage 1 for up to this many control steps rather than its policy's episode (4
    /// simulated seconds), still ending once held; counted at the paper's rate, as
    /// `stage1_held_steps` is, so that a faster rate gets as long. A third of the shipped
    /// Stage 1's misses from fresh placements reach the pose between steps 100 and 200.
    /// Planning for the hand it is 200 (Table I, session 47 in `results/TRAINING.md`: as many
    /// cubes with rollback, fewer actions, more open loop).
    pub stage1_steps: Option<usize>,
}

impl Driving {
    pub const FOR_HAND: Driving = Driving {
        gradual_opening: true,
        stage1_held_steps: Some(5),
        stage1_steadying: None,
        stage1_control_rate: None,
        stage1_steps: Some(200),
    };
}

/// A reflex against drops in Stage 1: when the cube strays more than `radius` metres across
/// the palm from its resting point, the hand takes the neutral action for `steps` control
/// steps, and then the policy goes on. It fires again only once the cube has come back within
/// the radius. Every drop begins with the cube sliding away from the centre of the palm, but
/// so do half of the runs that keep it: in the operator, holding still 5 steps past 3 cm
/// missed more poses and dropped more cubes (`results/TRAINING.md`, session 15), so it
/// is off by default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Steadying {
    pub radius: f64,
    pub steps: usize,
}

/// One Stage 1 run's [`Steadying`]: whether the hand holds still at this step.
pub struct Steadier {
    steadying: Steadying,
    centre: [f64; 3],
    armed: bool,
    holding_for: usize,
}

impl Steadier {
    pub fn new(steadying: Steadying, centre: [f64; 3]) -> Steadier {
        Steadier {
            steadying,
            centre,
            armed: true,
            holding_for: 0,
        }
    }

    /// Whether the hand takes the neutral action at this step, given where the cube is.
    pub fn holds(&mut self, sim: &Sim) -> bool {
        let strayed = distance_across_palm(sim, self.centre) > self.steadying.radius;
        if !strayed {
            self.armed = true;
        }
        if self.holding_for > 0 {
            self.holding_for -= 1;
            return true;
        }
        if strayed && self.armed {
            self.armed = false;
            self.holding_for = self.steadying.steps.saturating_sub(1);
            return true;
        }
        false
    }
}

/// The action at this step of a Stage 1 run: the neutral action while `steadier` holds the
/// hand still, otherwise the policy's (`act`).
pub fn steadied_action(
    steadier: Option<&mut Steadier>,
    sim: &Sim,
    act: impl FnOnce() -> Vec<f64>,
) -> Vec<f64> {
    if steadier.is_some_and(|steadier| steadier.holds(sim)) {
        vec![0.0; HAND_ACTUATORS]
    } else {
        act()
    }
}

/// How far the cube lies from `centre` across the palm (horizontally), metres.
pub fn distance_across_palm(sim: &Sim, centre: [f64; 3]) -> f64 {
    let [x, y, _] = sim.object_pose().position;
    (x - centre[0]).hypot(y - centre[1])
}

/// Control steps that open the hand and let the cube settle before a stage's policy acts
/// (see [`drive`]).
pub const OPENING_STEPS: usize = 2 * SETTLE_STEPS;

/// Runs a policy for its episode, as its training and `eval-stage` do: the policies learn to
/// reach their goal by the episode's last step and hold it there. The stage is judged at its
/// end, and `stop` may end it sooner: it is asked after every step. (Ending at the first step
/// the goal is met let go of cubes caught mid-turn: they dropped half again as often.)
///
/// First the hand opens flat (the model's zero pose) and then takes the neutral action,
/// `SETTLE_STEPS` each, with the cube on its palm: every training episode starts that way,
/// from a hand placed flat and left to settle, while the previous stage leaves the fingers
/// wherever it ended (the paper's "problematic end states"). Going straight to the neutral
/// action from such an end state throws the cube off the palm; opening at once still does
/// now and then, which `gradual_opening` avoids. These steps count as control steps, not as
/// an action.
///
/// The policy then acts for `episode`'s control steps at its rate (the one it was trained at,
/// unless the operator asks for another); the hand opens at the paper's rate.
fn drive(
    sim: &mut Sim,
    act: impl FnMut(&Sim) -> Vec<f64>,
    resting_z: f64,
    gradual_opening: bool,
    stop: &mut dyn FnMut(&Sim) -> bool,
    watch: Watch,
    episode: (usize, ControlRate),
) -> StageRun {
    let mut run = StageRun::default();
    let open = sim.scene().open_hand_action();
    let from = if gradual_opening { sim.action() } else { open };
    let mut step = 0;
    let settling = |_: &Sim| {
        step += 1;
        if step > SETTLE_STEPS {
            return vec![0.0; HAND_ACTUATORS];
        }
        let t = step as f64 / SETTLE_STEPS as f64;
        from.iter()
            .zip(&open)
            .map(|(a, b)| a + t * (b - a))
            .collect()
    };
    let never = &mut |_: &Sim| false;
    let opening = (OPENING_STEPS, ControlRate::PAPER);
    if !advance(sim, settling, opening, resting_z, watch, never, &mut run) {
        return run;
    }
    advance(sim, act, episode, resting_z, watch, stop, &mut run);
    run
}

/// Up to `steps` control steps of `act` at `rate`, ending early once `stop` says so; false
/// if the cube dropped or the physics blew up (noted in `run`).
fn advance(
    sim: &mut Sim,
    mut act: impl FnMut(&Sim) -> Vec<f64>,
    (steps, rate): (usize, ControlRate),
    resting_z: f64,
    watch: Watch,
    stop: &mut dyn FnMut(&Sim) -> bool,
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
        if sim.step_substeps(rate.substeps()).is_err() {
            run.diverged = true;
            return false;
        }
        watch(sim);
        if is_dropped(sim, resting_z) {
            run.dropped = true;
            return false;
        }
        if stop(sim) {
            break;
        }
    }
    true
}

/// Stage 1 by a CubeRotEnv policy.
pub struct PolicyStage1 {
    pub policy: Policy,
    /// The success test the policy was trained on, whose desired goal it is given and which
    /// its run is held to: the paper's in some mode, or one that also needs the cube left
    /// square.
    pub goal: RotGoal,
    /// What the policy was trained to see beyond the paper's observations
    /// ([`CubeRotEnv::with_view`]).
    pub view: View,
    pub driving: Driving,
    /// The control rate the policy was trained at ([`trained_control_rate`]).
    pub control_rate: ControlRate,
}

impl PolicyStage1 {
    /// The success test in `mode` a Stage 1 policy (loaded from `path`) was trained on, told
    /// by the size of its goal input: 7, the paper's; 8, the cube left square as well.
    pub fn trained_goal(
        policy: &Policy,
        mode: RotMode,
        path: &Path,
    ) -> Result<RotGoal, CheckpointError> {
        let size = policy.card.dims.goal;
        RotGoal::of_size(mode, size).ok_or_else(|| {
            wrong_goal_size(path, "1 (CubeRotEnv)", "7 numbers (the pose) or 8", size)
        })
    }

    /// What a Stage 1 policy (loaded from `path`) sees, told by the size of its observation
    /// input beyond [`CubeRotEnv::PAPER_OBSERVATION`].
    pub fn trained_view(policy: &Policy, path: &Path) -> Result<View, CheckpointError> {
        trained_view(
            policy,
            path,
            "1 (CubeRotEnv)",
            CubeRotEnv::PAPER_OBSERVATION,
        )
    }
}

/// The error for a policy whose goal input fits neither of a stage's goals.
fn wrong_goal_size(path: &Path, stage: &str, expected: &str, size: usize) -> CheckpointError {
    CheckpointError::Mismatch {
        path: path.to_path_buf(),
        message: format!(
            "a Stage {stage} policy takes a goal of {expected} (and the cube's misalignment), \
             this one {size}: pass a policy trained for that stage"
        ),
    }
}

impl Stage1 for PolicyStage1 {
    fn run(&mut self, sim: &mut Sim, position: [f64; 3], target: Quat, watch: Watch) -> StageRun {
        let goal = self.goal.desired(&pose_goal(position, target));
        let (policy, view) = (&self.policy, self.view);
        let reached = pose_reached(self.goal);
        let rate = self
            .driving
            .stage1_control_rate
            .unwrap_or(self.control_rate);
        // Held, and run, for as long as at the paper's rate, however often the policy acts.
        let at_rate = |paper_steps: usize| paper_steps * SUBSTEPS / rate.substeps();
        let held_steps = self.driving.stage1_held_steps.map(at_rate);
        let steps = self
            .driving
            .stage1_steps
            .map_or(rate.episode_steps(), at_rate);
        let mut running = 0;
        let mut held = |sim: &Sim| {
            held_steps.is_some_and(|steps| {
                running = if reached(sim, position, target) {
                    running + 1
                } else {
                    0
                };
                running >= steps
            })
        };
        let mut steadier = self
            .driving
            .stage1_steadying
            .map(|steadying| Steadier::new(steadying, position));
        let test = self.goal;
        let mut acting = policy.episode();
        let act = |sim: &Sim| {
            steadied_action(steadier.as_mut(), sim, || {
                let achieved = || {
                    let pose = sim.object_pose();
                    achieved_goal(&test, sim, &pose_goal(pose.position, pose.orientation))
                };
                let observation = rot_observation(sim, view, None);
                acting.act_toward(&observation, &goal, achieved, &test)
            })
        };
        drive(
            sim,
            act,
            position[2],
            self.driving.gradual_opening,
            &mut held,
            watch,
            (steps, rate),
        )
    }
}

/// Stage 2 by a LayerOpEnv U' policy, which sees the cube as LayerOpEnv does on the `cube`
/// scene ([`CubeLayer`]): the layer that stays, and the angle turned since the stage began.
pub struct PolicyStage2 {
    pub policy: Policy,
    /// The success test the policy was trained on, whose desired goal it is given: the
    /// paper's, or one that also needs the cube left square.
    pub goal: LayerGoal,
    /// What the policy was trained to see beyond the paper's observations
    /// ([`CubeLayer::with_view`]).
    pub view: View,
    pub resting_z: f64,
    pub driving: Driving,
    /// The control rate the policy was trained at ([`trained_control_rate`]).
    pub control_rate: ControlRate,
}

impl PolicyStage2 {
    /// The success test a Stage 2 policy (loaded from `path`) was trained on, told by the
    /// size of its goal input: 1, the paper's; 2, the cube left square as well.
    pub fn trained_goal(policy: &Policy, path: &Path) -> Result<LayerGoal, CheckpointError> {
        let size = policy.card.dims.goal;
        LayerGoal::of_size(size).ok_or_else(|| {
            wrong_goal_size(
                path,
                "2 (LayerOpEnv)",
                "1 number (the layer angle) or 2",
                size,
            )
        })
    }

    /// What a Stage 2 policy (loaded from `path`) sees, told by the size of its observation
    /// input beyond [`CubeLayer::PAPER_OBSERVATION`].
    pub fn trained_view(policy: &Policy, path: &Path) -> Result<View, CheckpointError> {
        trained_view(policy, path, "2 (LayerOpEnv)", CubeLayer::PAPER_OBSERVATION)
    }
}

/// The control rate a policy (loaded from `path`) was trained at, as its card's training
/// environment records it (`control_substeps`): the paper's where the card does not say
/// (every policy trained before the rate could be chosen).
pub fn trained_control_rate(policy: &Policy, path: &Path) -> Result<ControlRate, CheckpointError> {
    let recorded = &policy.card.metadata["environment"]["control_substeps"];
    let Some(substeps) = recorded.as_u64() else {
        return match recorded {
            serde_json::Value::Null => Ok(ControlRate::PAPER),
            other => Err(bad_control_substeps(path, other.to_string())),
        };
    };
    ControlRate::every(substeps as usize).map_err(|message| bad_control_substeps(path, message))
}

fn bad_control_substeps(path: &Path, message: String) -> CheckpointError {
    CheckpointError::Mismatch {
        path: path.to_path_buf(),
        message: format!(
            "its card's control_substeps is not a rate the environments run at ({message}): \
             restore the card from its run"
        ),
    }
}

/// What a policy (loaded from `path`) for `stage` sees, told from the size of its observation
/// input: the stage's `paper` numbers, or more for a view beyond the paper's.
fn trained_view(
    policy: &Policy,
    path: &Path,
    stage: &str,
    paper: usize,
) -> Result<View, CheckpointError> {
    let view_of = |size: usize| {
        View::after(paper, size).ok_or_else(|| CheckpointError::Mismatch {
            path: path.to_path_buf(),
            message: format!(
                "a Stage {stage} policy observes {paper} numbers (one more with the cube's \
                 misalignment, six more with the grip), this one {size}: pass a policy trained \
                 for that stage"
            ),
        })
    };
    let view = view_of(policy.card.dims.observation)?;
    for partner in &policy.card.partners {
        let partner_view = view_of(partner.dims.observation)?;
        if !partner_view.leads(view) {
            return Err(CheckpointError::Mismatch {
                path: path.to_path_buf(),
                message: format!(
                    "its member {} sees the {}, which is not the leading part of what its first \
                     member sees (the {}): join them with the member that sees more first, or \
                     with views that extend one another",
                    partner.source.display(),
                    partner_view.name().unwrap_or("paper's observations"),
                    view.name().unwrap_or("paper's observations"),
                ),
            });
        }
    }
    Ok(view)
}

/// The cube-frame face whose outward normal points most nearly up in the world.
pub fn face_up(sim: &Sim) -> Face {
    face_toward(&sim.object_pose().orientation, UP)
}

const UP: [f64; 3] = [0.0, 0.0, 1.0];

impl Stage2 for PolicyStage2 {
    fn run(&mut self, sim: &mut Sim, watch: Watch) -> StageRun {
        let Some(view) = CubeLayer::start(sim, UP, rotation::IDENTITY) else {
            return StageRun::default();
        };
        let mut view = view.with_view(self.view);
        let (test, goal) = (self.goal, self.goal.desired(FRAC_PI_2));
        let mut acting = self.policy.episode();
        drive(
            sim,
            |sim| {
                let observation = view.observe(sim);
                let achieved = || test.achieved(view.turned(), cube_misalignment(sim));
                acting.act_toward(&observation, &goal, achieved, &test)
            },
            self.resting_z,
            self.driving.gradual_opening,
            &mut |_| false,
            watch,
            (self.control_rate.episode_steps(), self.control_rate),
        )
    }
}

/// A Stage 1 that records where each of its runs hands over to the policy: the physics state
/// once the hand has opened (after [`OPENING_STEPS`]), the pose asked for, and whether the
/// run then failed ([`RecordedFailure::DroppedOrMissed`]: it dropped the cube, or ended
/// without the pose `accepts`, the operator's check after Stage 1). A run that dropped the
/// cube while the hand opened records nothing.
///
/// [`RecordedFailure::DroppedOrMissed`]: dexcube_env::RecordedFailure::DroppedOrMissed
pub struct RecordingStage1<'a> {
    pub inner: &'a mut dyn Stage1,
    pub starts: &'a mut Vec<RecordedStart>,
    pub accepts: &'a (dyn Fn(&Sim, [f64; 3], Quat) -> bool + Sync),
}

impl Stage1 for RecordingStage1<'_> {
    fn run(&mut self, sim: &mut Sim, position: [f64; 3], target: Quat, watch: Watch) -> StageRun {
        let (mut steps, mut state) = (0, None);
        let mut recording = |sim: &mut Sim| {
            watch(sim);
            steps += 1;
            if steps == OPENING_STEPS {
                state = Some(sim.physics_state());
            }
        };
        let run = self.inner.run(sim, position, target, &mut recording);
        if let Some(state) = state {
            self.starts.push(RecordedStart {
                state,
                goal: pose_goal(position, target),
                failed: run.dropped || run.diverged || !(self.accepts)(sim, position, target),
            });
        }
        run
    }
}

/// A Stage 2 that records where each of its runs hands over to the policy: the physics state
/// once the hand has opened (after [`OPENING_STEPS`]), the quarter turn asked for, the
/// angle the layer had already turned while the hand opened (the policy's view counts from
/// the stage's start) and the face whose layer turns, and whether the run then failed by the
/// square test ([`LayerGoal::square`]: the top layer turned within 0.1 rad of U', with the
/// cube in its good state, and not dropped). A run that dropped the cube while the hand
/// opened records nothing.
pub struct RecordingStage2<'a> {
    pub inner: &'a mut dyn Stage2,
    pub starts: &'a mut Vec<RecordedStart>,
}

impl Stage2 for RecordingStage2<'_> {
    fn run(&mut self, sim: &mut Sim, watch: Watch) -> StageRun {
        let Some(mut view) = CubeLayer::start(sim, UP, rotation::IDENTITY) else {
            return self.inner.run(sim, watch);
        };
        let (mut steps, mut start) = (0, None);
        let mut recording = |sim: &mut Sim| {
            watch(sim);
            steps += 1;
            // Every step, so that the layer angle unwraps as the policy's own view does.
            view.follow(sim);
            if steps == OPENING_STEPS {
                start = Some((sim.physics_state(), view.start_goal(FRAC_PI_2)));
            }
        };
        let run = self.inner.run(sim, &mut recording);
        if let Some((state, goal)) = start {
            let test = LayerGoal::square();
            let misalignment = CubeState::read(sim).map_or(f64::INFINITY, |c| c.misalignment());
            let reached = test.is_success(
                &test.achieved(view.turned(), misalignment),
                &test.desired(FRAC_PI_2),
            );
            self.starts.push(RecordedStart {
                state,
                goal,
                failed: run.dropped || run.diverged || !reached,
            });
        }
        run
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

/// CubeRotEnv's success test `goal` judged on the physical cube: its pose, and for a test
/// that needs it, its good state. With the paper's test, the rollback's pose check after
/// Stage 1.
pub fn pose_reached(goal: RotGoal) -> impl Fn(&Sim, [f64; 3], Quat) -> bool {
    move |sim, position, target| {
        let pose = sim.object_pose();
        goal.is_success(
            &achieved_goal(&goal, sim, &pose_goal(pose.position, pose.orientation)),
            &goal.desired(&pose_goal(position, target)),
        )
    }
}
