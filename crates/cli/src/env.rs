//! `dexcube env`: look at the training environments from the command line, their spaces and
//! random-policy rollouts.

use std::process::ExitCode;

use anyhow::bail;
use clap::{Args, Subcommand, ValueEnum};
use dexcube_env::{
    ControlRate, EnvSettings, EnvSpec, GoalEnv, LayerMove, ObjectKind, PAPER_ANGLE_THRESHOLD,
    RecordedFailure, RotMode, Skill,
};
use dexcube_sim::Scene;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[derive(Subcommand)]
pub enum EnvCommand {
    /// Prints an environment's observation, goal and action sizes and its success test.
    Info(EnvChoice),
    /// Runs episodes with a policy and prints success and return per episode.
    Rollout(RolloutArgs),
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum EnvKind {
    /// CubeRotEnv, Stage 1.
    Rot,
    /// LayerOpEnv, Stage 2.
    Layer,
}

impl EnvKind {
    /// The name on the command line, and of run folders.
    pub fn name(self) -> &'static str {
        match self {
            EnvKind::Rot => "rot",
            EnvKind::Layer => "layer",
        }
    }

    /// The skill the environment learns.
    pub fn skill(self) -> Skill {
        match self {
            EnvKind::Rot => Skill::Rot,
            EnvKind::Layer => Skill::Layer,
        }
    }

    /// The stage's name in the paper's terms.
    pub fn stage(self) -> &'static str {
        match self {
            EnvKind::Rot => "Stage 1",
            EnvKind::Layer => "Stage 2",
        }
    }

    /// The `dexcube eval` flag that records this stage's starts.
    pub fn record_flag(self) -> &'static str {
        match self {
            EnvKind::Rot => "--record-starts",
            EnvKind::Layer => "--record-layer-starts",
        }
    }

    /// What `dexcube eval` marks as this stage's failure when it records the stage's starts.
    pub fn recorded_failure(self) -> RecordedFailure {
        match self {
            EnvKind::Rot => RecordedFailure::DroppedOrMissed,
            EnvKind::Layer => RecordedFailure::NotSquare,
        }
    }
}

#[derive(Args)]
pub struct EnvChoice {
    #[arg(value_enum)]
    pub env: EnvKind,
    /// CubeRotEnv's success test: paper (whole orientation), axis (the target face up, any
    /// yaw) or pair (the target face or its opposite up, any yaw).
    #[arg(long, default_value = "paper")]
    pub mode: RotMode,
    /// LayerOpEnv's move: U U' R R' F F'.
    #[arg(long = "move", default_value = "U'")]
    pub layer_move: LayerMove,
    /// The object on the palm: cube (the physical 2x2x2 the operator turns; LayerOpEnv's
    /// default), block (LayerOpEnv's two-layer block on one hinge) or rigid (CubeRotEnv's
    /// rigid cube, its default). Block and rigid are quicker to simulate.
    #[arg(long)]
    pub object: Option<ObjectKind>,
    /// On the physical cube only: success also needs the cube left in its good state (every
    /// cubelet within 0.1 rad of a quarter turn); the goal gains the cube's misalignment.
    /// The paper's tests read only the pose (CubeRotEnv) or the turned layer (LayerOpEnv).
    #[arg(long)]
    pub square: bool,
    /// CubeRotEnv on the physical cube only: success also needs the cube intact, no layer
    /// turned from where it was when the episode began (a layer pushed a whole quarter round
    /// leaves the cube square, but changes the puzzle). Implies --square.
    #[arg(long)]
    pub intact: bool,
    /// With --intact: a turned layer also ends the episode as a failure that lasts (absorbing),
    /// as a drop does, rather than leaving the steps after it, which do not show the turn, to
    /// fail one by one.
    #[arg(long, requires = "intact")]
    pub turn_ends: bool,
    /// On the physical cube only: the observation gains the cube's misalignment (the largest
    /// angle of a cubelet off a quarter turn, in tenths of a radian), which the good state's
    /// test reads and the paper's observations (61 for CubeRotEnv, 62 for LayerOpEnv) do not
    /// show.
    #[arg(long)]
    pub see_misalignment: bool,
    /// On the physical cube only: the observation gains the hand's grip, the normal force in
    /// newtons with which the thumb, each finger and the palm press on the cube (six numbers,
    /// after the misalignment if that is seen too), which the paper's observations show
    /// only through the cube's motion.
    #[arg(long)]
    pub see_grip: bool,
    /// The policy acts every N physics substeps of 2 ms instead of the paper's 20 (a faster
    /// control rate), with as many more steps to an episode, so that each still lasts 4
    /// simulated seconds; placing and settling keep the paper's rate. N divides 20.
    #[arg(long = "control-substeps", value_name = "N", default_value_t = ControlRate::PAPER)]
    pub control_rate: ControlRate,
    /// The success test's angle threshold in radians: of the pose for CubeRotEnv, of the
    /// layer for LayerOpEnv (paper: 0.1). A tighter one trains a policy to end nearer its
    /// goal than the paper's test asks; `eval-stage` and the operator keep the paper's. A
    /// resume must say it again.
    #[arg(long, value_name = "RAD", default_value_t = PAPER_ANGLE_THRESHOLD, value_parser = angle_threshold)]
    pub angle_threshold: f64,
}

impl EnvChoice {
    /// The flags as an environment's settings.
    pub fn settings(&self) -> EnvSettings {
        EnvSettings {
            mode: (self.env == EnvKind::Rot).then(|| self.mode.name().to_string()),
            layer_move: (self.env == EnvKind::Layer).then(|| self.layer_move.name().to_string()),
            object: self.object.map(|o| o.name().to_string()),
            square: self.square,
            intact: self.intact,
            turn_ends: self.turn_ends,
            see_misalignment: self.see_misalignment,
            see_grip: self.see_grip,
            control_substeps: Some(self.control_rate.substeps()),
            angle_threshold: Some(self.angle_threshold),
            ..EnvSettings::default()
        }
    }

    /// The chosen environment, checked.
    pub fn spec(&self) -> anyhow::Result<EnvSpec> {
        self.settings()
            .resolve(self.env.skill())
            .map_err(anyhow::Error::msg)
    }

    /// Builds the chosen environment; LayerOpEnv samples training goals.
    pub fn build(&self) -> anyhow::Result<Box<dyn GoalEnv>> {
        let make = self.spec()?.maker(None).map_err(anyhow::Error::msg)?;
        Ok(make() as Box<dyn GoalEnv>)
    }
}

/// `--physics-spread S` for `train` and `eval-stage`: how far each episode's physics is
/// varied, 0 (the scene's own) or more.
pub fn physics_spread(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(spread) if spread >= 0.0 && spread.is_finite() => Ok(spread),
        _ => Err(format!(
            "--physics-spread must be 0 or more (0.3 scales each by 1/1.3 to 1.3), not '{text}'"
        )),
    }
}

/// `--angle-threshold RAD` for `train`: a success test's angle threshold.
fn angle_threshold(text: &str) -> Result<f64, String> {
    angle_flag("--angle-threshold", " (the paper's is 0.1)", text)
}

/// An angle in radians given to `flag`, above 0 and below π; `hint` follows the range in the
/// refusal.
pub fn angle_flag(flag: &str, hint: &str, text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(angle) if angle > 0.0 && angle < std::f64::consts::PI => Ok(angle),
        _ => Err(format!(
            "{flag} must be an angle in radians above 0 and below π{hint}, not '{text}'"
        )),
    }
}

/// The object each environment held before the object was an option: runs and cards on it
/// keep their old names.
pub fn original_object(env: EnvKind) -> ObjectKind {
    env.skill().original_object()
}

/// `object`, if `env` can hold it.
pub fn suited(env: EnvKind, object: ObjectKind) -> anyhow::Result<ObjectKind> {
    match (env, object) {
        (EnvKind::Rot, ObjectKind::Block) => {
            bail!("CubeRotEnv holds the rigid or the physical cube: use --object rigid or cube")
        }
        (EnvKind::Layer, ObjectKind::Rigid) => {
            bail!("LayerOpEnv needs a layer to turn: use --object cube or block")
        }
        _ => Ok(object),
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub enum PolicyArg {
    /// Uniform random actions in [-1, 1]^20.
    Random,
    /// The neutral action (every actuator at the middle of its range).
    Zero,
}

#[derive(Args)]
pub struct RolloutArgs {
    #[command(flatten)]
    choice: EnvChoice,
    #[arg(long, value_enum, default_value = "random")]
    policy: PolicyArg,
    #[arg(long, default_value_t = 10)]
    episodes: u64,
    /// Episode i is reset with seed + i; the random policy draws from seed too.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

pub fn run(command: EnvCommand) -> anyhow::Result<ExitCode> {
    match command {
        EnvCommand::Info(choice) => info(&choice),
        EnvCommand::Rollout(args) => rollout(&args),
    }
}

fn info(choice: &EnvChoice) -> anyhow::Result<ExitCode> {
    let spec = choice.spec()?;
    let env = choice.build()?;
    let spaces = env.spaces();
    println!("{}", spec.name());
    println!("  observation: {} floats", spaces.observation);
    println!(
        "  goal:        {} floats (achieved_goal and desired_goal)",
        spaces.goal
    );
    println!(
        "  action:      {} floats in [-1, 1], absolute joint targets",
        spaces.action
    );
    println!(
        "  episode:     {} control steps of 20 x 0.002 s",
        dexcube_env::EPISODE_STEPS
    );
    let square = match (spec.square, spec.intact) {
        (_, true) => ", every cubelet within 0.1 rad of a quarter turn, no layer turned",
        (true, false) => ", every cubelet within 0.1 rad of a quarter turn",
        (false, false) => "",
    };
    let angle = choice.angle_threshold;
    match choice.env {
        EnvKind::Rot => println!(
            "  success:     position within 0.01 m and {} within {angle} rad{square}; reward 0, \
             else -1",
            match choice.mode {
                RotMode::Paper => "orientation",
                RotMode::Axis => "the target's up axis",
                RotMode::Pair => "the target's up axis, either way up,",
            }
        ),
        EnvKind::Layer => println!(
            "  success:     layer angle within {angle} rad of the goal{square}; reward 0, else -1"
        ),
    }
    Ok(ExitCode::SUCCESS)
}

fn rollout(args: &RolloutArgs) -> anyhow::Result<ExitCode> {
    let mut env = args.choice.build()?;
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let mut successes = 0;
    println!(
        "{} with the {} policy, seed {}",
        args.choice.spec()?.name(),
        policy_name(args.policy),
        args.seed
    );
    println!("episode  steps  return  success  final angle error (rad)");
    for episode in 0..args.episodes {
        env.reset(Some(args.seed.wrapping_add(episode)));
        let (mut total, mut steps) = (0.0, 0);
        let last = loop {
            let action: Vec<f64> = match args.policy {
                PolicyArg::Random => (0..20).map(|_| rng.random_range(-1.0..=1.0)).collect(),
                PolicyArg::Zero => vec![0.0; 20],
            };
            let t = env.step(&action);
            total += t.reward;
            steps += 1;
            if t.terminated || t.truncated {
                break t;
            }
        };
        successes += last.info.is_success as usize;
        let end = if last.info.dropped { " (dropped)" } else { "" };
        println!(
            "{episode:>7}  {steps:>5}  {total:>6.0}  {:>7}  {:.3}{end}",
            last.info.is_success, last.info.angle_error
        );
    }
    println!("success rate: {successes}/{}", args.episodes);
    Ok(ExitCode::SUCCESS)
}

fn policy_name(policy: PolicyArg) -> &'static str {
    match policy {
        PolicyArg::Random => "random",
        PolicyArg::Zero => "zero",
    }
}

/// Loads recorded starts of `stage` for `scene`, with what their failure marks mean, refusing
/// a file of another stage, another scene or another state size with a message that says so.
pub fn starts_for(
    path: &std::path::Path,
    scene: &std::sync::Arc<Scene>,
    stage: EnvKind,
) -> anyhow::Result<(
    std::sync::Arc<[dexcube_env::RecordedStart]>,
    RecordedFailure,
)> {
    let (starts, origin) = dexcube_rl::start_file::load_starts(path)?;
    if starts.is_empty() {
        bail!("{} holds no starts", path.display());
    }
    if origin.stage != stage.name() {
        bail!(
            "{} holds {} starts, not {}'s: record {} with `dexcube eval {} FILE`",
            path.display(),
            origin.stage,
            stage.name(),
            stage.name(),
            stage.record_flag()
        );
    }
    let name = scene.kind().name();
    if origin.scene != name {
        bail!(
            "{} holds starts on the '{}' scene, not '{name}': starts are recorded on the physical \
             cube, so train or evaluate with --object cube",
            path.display(),
            origin.scene
        );
    }
    let size = scene.physics_state_size();
    if let Some(start) = starts.iter().find(|s| s.state.len() != size) {
        bail!(
            "{} holds physics states of {} numbers where this scene's have {size}: it was \
             recorded with another scene file or MuJoCo; record it again (its command: {})",
            path.display(),
            start.state.len(),
            origin.command
        );
    }
    Ok((starts.into(), origin.failure))
}
