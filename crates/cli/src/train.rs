//! `dexcube train`: DDPG + HER on CubeRotEnv or LayerOpEnv, with a progress bar, metrics CSV,
//! learning curves, checkpoints every epoch, the best policy kept, and resume.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;

use anyhow::bail;
use clap::Args;
use dexcube_env::layer::{LayerGoals, LayerMove};
use dexcube_env::{
    ControlRate, CubeRotEnv, EpisodeSettings, GoalEnv, GoalLead, LayerOpEnv, StartMix, StartPick,
};
use dexcube_rl::checkpoint::CheckpointError;
use dexcube_rl::handover::{FarHandover, Handover};
use dexcube_rl::residual::{ResidualEnv, ResidualSetting, check_scale};
use dexcube_rl::start_gesture::StartGesture;
use dexcube_rl::start_route::{RoutedEpisodes, StartRoute};
use dexcube_rl::{DdpgHerConfig, Policy, TrainOptions, train};
use dexcube_sim::Scene;

use crate::env::{
    EnvChoice, EnvKind, PAPER_ANGLE_THRESHOLD, angle_flag, physics_spread, starts_for,
};

/// How training collects experience, shared by `train` and `bench rl`. Eight environments
/// on two threads balance physics against the 40 batches of a cycle on a 2-core machine.
#[derive(Args)]
pub struct Workers {
    /// Environments stepped together; each gives one episode per cycle.
    #[arg(long, default_value_t = 8)]
    pub envs: usize,
    /// Threads stepping the environments.
    #[arg(long, default_value_t = 2)]
    pub threads: usize,
    /// Seed of everything random: weights, episodes, exploration.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

/// Trains an atomic action with DDPG + HER (the HER baselines' hyperparameters).
#[derive(Args)]
pub struct TrainArgs {
    #[command(flatten)]
    choice: EnvChoice,
    /// Epochs of 50 cycles (each: one episode per environment, then 40 batches).
    #[arg(long, default_value_t = 50)]
    epochs: usize,
    #[command(flatten)]
    workers: Workers,
    /// Output folder (default: runs/<env>-<mode or move>-seed<seed>).
    #[arg(long, conflicts_with = "resume")]
    out: Option<PathBuf>,
    /// Continue the run in this folder from its last checkpoint.
    #[arg(long, value_name = "DIR")]
    resume: Option<PathBuf>,
    /// Warm start from the networks and normalisers of the run in this folder (for example
    /// to fine-tune on another success test or goal range); a new run in --out.
    #[arg(long, value_name = "DIR", conflicts_with = "resume")]
    init: Option<PathBuf>,
    /// Warm start the actor and its normalisers from this policy (PREFIX.safetensors and
    /// PREFIX.json, e.g. models/rot, which may be an earlier epoch than a run's last
    /// checkpoint). The critic comes from the --init run, or without one starts afresh: then
    /// give it --critic-only-epochs to learn the policy's values first.
    #[arg(long, value_name = "PREFIX", conflicts_with = "resume")]
    init_actor: Option<PathBuf>,
    /// LayerOpEnv only: train on the evaluation goal, exactly a quarter turn, rather than
    /// goals uniform over it (HER still relabels with the angles reached on the way).
    #[arg(long)]
    quarter_goals: bool,
    /// Train only the critic for this run's first N epochs, the actor held as loaded: for a
    /// warm start (--init) onto another object or success test (0: DDPG as published). A
    /// resumed run keeps the number it began with.
    #[arg(long, default_value_t = 0, value_name = "N", conflicts_with = "resume")]
    critic_only_epochs: usize,
    /// Keep the policy of every this many epochs under DIR/snapshots (0: none).
    #[arg(long, default_value_t = 5)]
    snapshot_every: usize,
    /// Units in each of the networks' three hidden layers (the paper's 256). A warm start
    /// (--init, --init-actor) from narrower networks embeds them, so the wider networks begin
    /// acting as they did. A resume must say it again.
    #[arg(long, default_value_t = 256, value_name = "UNITS", value_parser = clap::value_parser!(u16).range(1..))]
    width: u16,
    /// Optimisation batches per cycle (HER baselines: 40).
    #[arg(long, default_value_t = 40)]
    batches: usize,
    /// Gaussian exploration noise as a share of the action range (HER baselines: 0.2).
    #[arg(long, value_name = "SHARE")]
    noise_eps: Option<f64>,
    /// Probability of a uniformly random action while exploring (HER baselines: 0.3).
    /// Fine-tuning a policy that already succeeds may want less of both.
    #[arg(long, value_name = "P")]
    random_eps: Option<f64>,
    /// Adam learning rate of the actor (HER baselines: 0.001).
    #[arg(long, value_name = "RATE")]
    actor_lr: Option<f64>,
    /// Fine-tuning: weight of a penalty on the actor's squared distance from the actor it
    /// starts from (--init or --init-actor), beside the action penalty (DDPG: 0).
    #[arg(long, default_value_t = 0.0, value_name = "WEIGHT")]
    anchor: f64,
    /// What dropping the cube is worth in the critic's targets, as a multiple of the floor
    /// -1/(1-γ) that missing for ever is worth (DDPG: 1). A resume must say it again.
    #[arg(long, default_value_t = 1.0, value_name = "MULTIPLE")]
    drop_cost: f64,
    /// Train without Hindsight Experience Replay (plain DDPG), for ablations.
    #[arg(long)]
    no_her: bool,
    /// Train with TD3's critics instead of DDPG's (Fujimoto et al. 2018: twin critics, target
    /// policy smoothing, the actor updated every second step), HER and the rest unchanged. A
    /// resume must say it again.
    #[arg(long)]
    td3: bool,
    /// On the physical cube: begin a share of episodes (--start-share) from the starts
    /// recorded in this file, where the operator hands the cube over, rather than from a fresh
    /// placement: Stage 1's (`dexcube eval --record-starts`) for rot, Stage 2's (`dexcube eval
    /// --record-layer-starts`) for layer U'. A resume must name the same.
    #[arg(long, value_name = "FILE")]
    starts: Option<PathBuf>,
    /// With --starts, the probability that an episode begins from one of them.
    #[arg(long, default_value_t = 0.5, value_name = "P", requires = "starts")]
    start_share: f64,
    /// With --starts, how many times as often a start the recorded policy failed from (Stage
    /// 1: dropped the cube; Stage 2: did not leave the layer turned with the cube square) is
    /// drawn as one it succeeded from (1: all alike).
    #[arg(
        long,
        alias = "dropped-weight",
        default_value_t = 1.0,
        value_name = "W",
        requires = "starts"
    )]
    failed_weight: f64,
    /// Vary the physics of each training episode by this spread S (domain randomisation):
    /// every geom's friction, the object's mass and every joint's damping are each scaled by
    /// a factor drawn log-uniform between 1/(1+S) and 1+S from the episode's seed; the test
    /// episodes of each epoch are varied alike (0: the scene's own physics, as the paper). A
    /// resume must say it again.
    #[arg(long, default_value_t = 0.0, value_name = "S", value_parser = physics_spread)]
    physics_spread: f64,
    /// Train a residual on top of this policy (residual policy learning: any card, e.g.
    /// models/rot-lead-handover, acting as it is deployed) rather than a policy of its own:
    /// the actor observes the observation followed by the base's action, its action times
    /// --residual-scale is added to the base's, and it starts at zero, so the run first acts
    /// as the base. `dexcube residual` ships the base and a snapshot as one policy. The
    /// environment (view, success test) must be the one the base was trained on. A resume
    /// must say it again.
    #[arg(long, value_name = "PREFIX", conflicts_with_all = ["init", "init_actor"])]
    residual_of: Option<PathBuf>,
    /// With --residual-of, the share of the action range the residual may move the base's
    /// action by.
    #[arg(
        long,
        default_value_t = 0.1,
        value_name = "S",
        requires = "residual_of"
    )]
    residual_scale: f64,
}

/// Redraws a training run's learning curve (RUN/success.png) from its checkpoint, for a run
/// trained on a machine that could not draw it (no fonts); or, given several runs and
/// `--out`, draws their test success as a mean with a band of one standard deviation across
/// seeds, a curve per environment (the paper's training-curve figures), with a CSV beside it.
#[derive(Args)]
pub struct PlotArgs {
    /// Run folders, as written by `dexcube train` (each holds checkpoint/state.json).
    #[arg(required = true)]
    runs: Vec<PathBuf>,
    /// Draw the runs across seeds into this PNG (and the same figures into its .csv).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn plot(args: PlotArgs) -> anyhow::Result<ExitCode> {
    let path = match (&args.out, args.runs.as_slice()) {
        (None, [run]) => dexcube_rl::train::replot(run)?,
        (None, _) => bail!("several runs are drawn across seeds into one figure: pass --out PNG"),
        (Some(out), runs) => {
            let curves = dexcube_rl::seeds::seed_curves(runs)?;
            for curve in &curves {
                let last = curve.points.last().copied().unwrap_or_default();
                println!(
                    "{}: seeds {:?}, {} epochs in common, test success at {} episodes {:.2} ± {:.2}",
                    curve.label,
                    curve.seeds,
                    curve.points.len(),
                    last.0,
                    last.1,
                    last.2
                );
            }
            dexcube_rl::seeds::plot_seed_curves(&curves, out)?
        }
    };
    println!("{}", path.display());
    Ok(ExitCode::SUCCESS)
}

/// Several policies made into one: `average` (their weights) or `ensemble` (their actions).
#[derive(Args)]
pub struct CombineArgs {
    /// The policies, each as the path of its .safetensors and .json less the extension.
    #[arg(required = true, num_args = 2..)]
    policies: Vec<PathBuf>,
    /// Where to write the result (PATH.safetensors and PATH.json).
    #[arg(long)]
    out: PathBuf,
}

/// How `combine` makes one policy of several.
#[derive(Clone, Copy)]
pub enum Combination {
    /// The mean of the actors' weights, with their normalisers pooled (stochastic weight
    /// averaging over one run's snapshots).
    Average,
    /// The mean of the actors' actions, each member keeping its own weights and normalisers.
    Ensemble,
}

pub fn combine(how: Combination, args: CombineArgs) -> anyhow::Result<ExitCode> {
    let members: Vec<String> = args
        .policies
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    type Make = fn(&[PathBuf], &std::path::Path, &str) -> Result<(), CheckpointError>;
    let (name, verb, make): (_, _, Make) = match how {
        Combination::Average => ("average", "averaged", Policy::average),
        Combination::Ensemble => ("ensemble", "joined", Policy::ensemble),
    };
    let command = format!(
        "dexcube {name} {} --out {}",
        members.join(" "),
        args.out.display()
    );
    make(&args.policies, &args.out, &command)?;
    println!(
        "{verb} {} policies into {}",
        members.len(),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct GuideArgs {
    /// The policy to guide (a single one or an ensemble), as the path of its .safetensors and
    /// .json less the extension.
    policy: PathBuf,
    /// The training run whose critics choose (its folder, with checkpoint/): the policy's
    /// own, or one trained on the same observations, goals and actions.
    #[arg(long, value_name = "RUN")]
    critics: PathBuf,
    /// How many actions beside the policy's own the critics weigh at each step.
    #[arg(long, default_value_t = 32, value_name = "K")]
    candidates: usize,
    /// How far each candidate lies from the policy's action: this times a standard normal
    /// direction per actuator (the action range is 2 wide).
    #[arg(long, default_value_t = 0.1, value_name = "S")]
    spread: f64,
    /// The seed the candidates' directions are drawn from, once.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Where to write the result (PATH.safetensors and PATH.json).
    #[arg(long)]
    out: PathBuf,
}

pub fn guide(args: GuideArgs) -> anyhow::Result<ExitCode> {
    let command = format!(
        "dexcube guide {} --critics {} --candidates {} --spread {} --seed {} --out {}",
        args.policy.display(),
        args.critics.display(),
        args.candidates,
        args.spread,
        args.seed,
        args.out.display()
    );
    let choice = (args.candidates, args.spread, args.seed);
    Policy::guide(&args.policy, &args.critics, choice, &args.out, &command)?;
    println!(
        "{} guided by the critics of {} into {}",
        args.policy.display(),
        args.critics.display(),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct GoalLeadArgs {
    /// The policy to lead (a single one, an ensemble or a guided one), as the path of its
    /// .safetensors and .json less the extension.
    policy: PathBuf,
    /// The share of the angle (and for a pose, the distance) still to go that is added to the
    /// goal the policy is shown.
    #[arg(long, value_name = "SHARE", value_parser = lead_share)]
    share: f64,
    /// Only while the angle still to go is under this many radians; further off, the policy is
    /// shown its goal as it is.
    #[arg(long, default_value_t = 0.5, value_name = "RAD", value_parser = lead_within)]
    within: f64,
    /// Where to write the result (PATH.safetensors and PATH.json).
    #[arg(long)]
    out: PathBuf,
}

fn lead_share(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(share) if share > 0.0 && share.is_finite() => Ok(share),
        _ => Err(format!(
            "--share must be a positive number (0.5 shows the goal half its error further on), \
             not '{text}'"
        )),
    }
}

fn lead_within(text: &str) -> Result<f64, String> {
    angle_flag("--within", "", text)
}

pub fn goal_lead(args: GoalLeadArgs) -> anyhow::Result<ExitCode> {
    let command = format!(
        "dexcube goal-lead {} --share {} --within {} --out {}",
        args.policy.display(),
        args.share,
        args.within,
        args.out.display()
    );
    let lead = GoalLead {
        share: args.share,
        within: args.within,
    };
    Policy::led(&args.policy, lead, &args.out, &command)?;
    println!(
        "{} shown its goal led on by {} within {} rad into {}",
        args.policy.display(),
        args.share,
        args.within,
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct NearestFrameArgs {
    /// The policy (any but one with a residual), as the path of its .safetensors and .json
    /// less the extension.
    policy: PathBuf,
    /// Where to write the result (PATH.safetensors and PATH.json).
    #[arg(long)]
    out: PathBuf,
}

pub fn nearest_frame(args: NearestFrameArgs) -> anyhow::Result<ExitCode> {
    let command = format!(
        "dexcube nearest-frame {} --out {}",
        args.policy.display(),
        args.out.display()
    );
    Policy::in_nearest_frame(&args.policy, &args.out, &command)?;
    println!(
        "{} shown the cube in the frame nearest its goal into {}",
        args.policy.display(),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct ResidualArgs {
    /// The base, the policy the residual was trained on top of (`train --residual-of`), as
    /// the path of its .safetensors and .json less the extension.
    base: PathBuf,
    /// The residual's actor: a snapshot (or the best or last policy) of that run.
    actor: PathBuf,
    /// Where to write the result (PATH.safetensors and PATH.json).
    #[arg(long)]
    out: PathBuf,
}

/// Ships a residual with its base as one policy, acting as the base with the residual's
/// correction added.
pub fn residual(args: ResidualArgs) -> anyhow::Result<ExitCode> {
    let command = format!(
        "dexcube residual {} {} --out {}",
        args.base.display(),
        args.actor.display(),
        args.out.display()
    );
    Policy::with_residual(&args.base, &args.actor, &args.out, &command)?;
    println!(
        "{} with the residual {} into {}",
        args.base.display(),
        args.actor.display(),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct HandoverArgs {
    /// The ensemble (led on or not), or with --let-go a single policy, as the path of its
    /// .safetensors and .json less the extension.
    policy: PathBuf,
    /// The member handed over to, counted from 0 in the order the ensemble was made
    /// (`models/rot`: 0 the seen run's `epoch-0047`, 1 `rot-dropw20`, 2 `rot-td3-19`).
    #[arg(long)]
    member: usize,
    /// Control steps in a row without progress (or the test met) before handing over; 0
    /// hands over at once, which acts as the member alone.
    #[arg(long, default_value_t = 25)]
    patience: usize,
    /// How much nearer its goal than it has yet been (radians) the cube must come for a step
    /// to count as progress.
    #[arg(long, default_value_t = 0.05, value_name = "RAD", value_parser = handover_progress)]
    progress: f64,
    /// The member that acts alone until the handover; without it the ensemble acts with its
    /// members' mean action until then.
    #[arg(long)]
    first: Option<usize>,
    /// Control steps the hand takes the neutral action for once handed over (the flat hand
    /// every episode settles on), before the member acts: letting go and trying again.
    #[arg(long, value_name = "STEPS")]
    let_go: Option<usize>,
    /// Another member for the stalls whose cube is still --far-beyond or more from its goal
    /// when the handover comes (session 60); the rest go to --member.
    #[arg(long, requires = "far_beyond")]
    far_member: Option<usize>,
    /// How far from its goal (radians) a stalled cube must be for --far-member to take it.
    #[arg(long, value_name = "RAD", requires = "far_member", value_parser = far_beyond)]
    far_beyond: Option<f64>,
    /// Where to write the result (PATH.safetensors and PATH.json).
    #[arg(long)]
    out: PathBuf,
}

fn far_beyond(text: &str) -> Result<f64, String> {
    angle_flag("--far-beyond", "", text)
}

fn handover_progress(text: &str) -> Result<f64, String> {
    angle_flag("--progress", "", text)
}

pub fn handover(args: HandoverArgs) -> anyhow::Result<ExitCode> {
    let command = format!(
        "dexcube handover {} --member {} --patience {} --progress {}{}{}{} --out {}",
        args.policy.display(),
        args.member,
        args.patience,
        args.progress,
        args.first
            .map(|k| format!(" --first {k}"))
            .unwrap_or_default(),
        args.let_go
            .map(|n| format!(" --let-go {n}"))
            .unwrap_or_default(),
        (args.far_member.zip(args.far_beyond))
            .map(|(k, b)| format!(" --far-member {k} --far-beyond {b}"))
            .unwrap_or_default(),
        args.out.display()
    );
    let handover = Handover {
        member: args.member,
        patience: args.patience,
        progress: args.progress,
        first: args.first,
        let_go: args.let_go,
        far: (args.far_member.zip(args.far_beyond))
            .map(|(member, beyond)| FarHandover { member, beyond }),
    };
    Policy::handing_over(&args.policy, handover, &args.out, &command)?;
    println!(
        "{} {handover} into {}",
        args.policy.display(),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct StartGestureArgs {
    /// The policy (single, ensemble, led on or handing over), as the path of its .safetensors
    /// and .json less the extension.
    policy: PathBuf,
    /// The actuators the gesture moves, counted from 0 in the hand's order (1 the wrist's
    /// flexion; 3, 6, 9 and 13 the first, middle, ring and little fingers' knuckles), comma
    /// separated.
    #[arg(long, value_delimiter = ',', required = true)]
    actuators: Vec<usize>,
    /// The action they take, from -1 (each joint at its lower limit: a knuckle straight) to 1
    /// (at its upper); the other actuators take the neutral action, 0.
    #[arg(long, allow_negative_numbers = true)]
    action: f64,
    /// Control steps the gesture lasts before the policy first acts.
    #[arg(long, default_value_t = 5)]
    steps: usize,
    /// An ensemble's member (0 is the first) that acts alone, before and after any handover,
    /// in the episodes that make the gesture: a specialist for the fingertips' side. Without
    /// it those episodes go on as the policy acts in every other.
    #[arg(long, value_name = "M")]
    member: Option<usize>,
    /// Where to write the result (PATH.safetensors and PATH.json).
    #[arg(long)]
    out: PathBuf,
}

pub fn start_gesture(args: StartGestureArgs) -> anyhow::Result<ExitCode> {
    // The fingertips' side is told from where the physical cube comes to rest on the palm.
    let resting = dexcube_operator::eval::resting_point()?;
    let gesture = StartGesture {
        actuators: args.actuators,
        action: args.action,
        steps: args.steps,
        below_y: resting[1],
        member: args.member,
    };
    let member = args
        .member
        .map_or(String::new(), |m| format!(" --member {m}"));
    let command = format!(
        "dexcube start-gesture {} --actuators {} --action {} --steps {}{member} --out {}",
        args.policy.display(),
        gesture.actuator_list(),
        gesture.action,
        gesture.steps,
        args.out.display()
    );
    Policy::with_start_gesture(&args.policy, gesture.clone(), &args.out, &command)?;
    println!(
        "{} making a start gesture, {gesture}, into {}",
        args.policy.display(),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct StartRouteArgs {
    /// The ensemble (handing over, making a start gesture or not), as the path of its
    /// .safetensors and .json less the extension.
    policy: PathBuf,
    /// The member (0 is the first) that acts alone, before and after any handover, in the
    /// episodes the route takes: by default those whose cube starts towards the thumb and
    /// that make no start gesture.
    #[arg(long, value_name = "M")]
    member: usize,
    /// Take instead the episodes that make the card's start gesture with the cube starting
    /// within DEG degrees of square to the hand (the yaw `stage2_start_geometry --max-yaw`
    /// reads).
    #[arg(long, value_name = "DEG")]
    near_square: Option<f64>,
    /// Where to write the result (PATH.safetensors and PATH.json).
    #[arg(long)]
    out: PathBuf,
}

pub fn start_route(args: StartRouteArgs) -> anyhow::Result<ExitCode> {
    let episodes = match args.near_square {
        Some(max_yaw) => RoutedEpisodes::GesturedNearSquare { max_yaw },
        // The thumb's side is told from where the physical cube comes to rest on the palm.
        None => RoutedEpisodes::TowardsThumb {
            below_x: dexcube_operator::eval::resting_point()?[0],
        },
    };
    let route = StartRoute {
        member: args.member,
        episodes,
    };
    let near_square = args
        .near_square
        .map_or(String::new(), |deg| format!(" --near-square {deg}"));
    let command = format!(
        "dexcube start-route {} --member {}{near_square} --out {}",
        args.policy.display(),
        route.member,
        args.out.display()
    );
    Policy::with_start_route(&args.policy, route, &args.out, &command)?;
    println!(
        "{} routing by its start, {route}, into {}",
        args.policy.display(),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// Refuses to resume a run with other recorded starts, at another control rate, under other
/// varied physics or to another angle threshold than it began with (its checkpoint's card
/// names them), since the card would then say it trained on starts, at a rate, on physics
/// or to a test it did not.
fn same_as_begun(run: &std::path::Path, args: &TrainArgs) -> anyhow::Result<()> {
    // A missing or unreadable checkpoint is the trainer's to report.
    let Ok(begun) = dexcube_rl::train::RunCurve::read(run) else {
        return Ok(());
    };
    let flags = |starts: Option<String>, share: Option<f64>, weight: f64| match (starts, share) {
        (Some(starts), Some(share)) => {
            format!("--starts {starts} --start-share {share} --failed-weight {weight}")
        }
        _ => "no --starts".to_string(),
    };
    let hidden = &begun.config.hidden;
    if hidden.iter().any(|&units| units != usize::from(args.width)) {
        bail!(
            "{} began with hidden layers of {hidden:?} units; resume it with the same --width, \
             not {}",
            run.display(),
            args.width
        );
    }
    let environment = &begun.environment;
    let begun = flags(
        environment["starts"].as_str().map(str::to_string),
        environment["start_share"].as_f64(),
        // Runs from before the weight drew every start alike; sessions 17 and 18 named it
        // after Stage 1's failures, drops.
        environment["failed_weight"]
            .as_f64()
            .or(environment["dropped_weight"].as_f64())
            .unwrap_or(1.0),
    );
    let now = flags(
        args.starts.as_ref().map(|p| p.display().to_string()),
        Some(args.start_share),
        args.failed_weight,
    );
    if begun != now {
        bail!(
            "{} began with {begun}; resume it with the same, not {now}",
            run.display()
        );
    }
    // Runs from before the rate could be chosen acted at the paper's.
    let begun_rate = environment["control_substeps"]
        .as_u64()
        .map_or(dexcube_sim::SUBSTEPS, |n| n as usize);
    if begun_rate != args.choice.control_rate.substeps() {
        bail!(
            "{} began acting every {begun_rate} substeps; resume it with --control-substeps \
             {begun_rate}, not {}",
            run.display(),
            args.choice.control_rate
        );
    }
    // Runs from before residuals could be trained trained policies of their own.
    let begun_residual: Option<ResidualSetting> =
        serde_json::from_value(environment["residual"].clone()).unwrap_or(None);
    let now_residual = residual_setting(args);
    if begun_residual != now_residual {
        let said = |setting: Option<ResidualSetting>| match setting {
            Some(r) => format!(
                "--residual-of {} --residual-scale {}",
                r.of.display(),
                r.scale
            ),
            None => "no --residual-of".to_string(),
        };
        bail!(
            "{} began with {}; resume it with the same, not {}",
            run.display(),
            said(begun_residual),
            said(now_residual)
        );
    }
    // Runs from before physics could be varied ran on the scene's own, and runs from before
    // the threshold could be chosen trained to the paper's.
    for (key, flag, given, before) in [
        (
            "physics_spread",
            "--physics-spread",
            args.physics_spread,
            0.0,
        ),
        (
            "angle_threshold",
            "--angle-threshold",
            args.choice.angle_threshold,
            PAPER_ANGLE_THRESHOLD,
        ),
    ] {
        let begun = environment[key].as_f64().unwrap_or(before);
        if begun != given {
            bail!(
                "{} began with {flag} {begun}; resume it with the same, not {given}",
                run.display()
            );
        }
    }
    Ok(())
}

/// The residual a run trains; none for a policy of its own.
fn residual_setting(args: &TrainArgs) -> Option<ResidualSetting> {
    args.residual_of.as_ref().map(|of| ResidualSetting {
        of: of.clone(),
        scale: args.residual_scale,
    })
}

/// Trains on the environments `make` makes, or with `residual` (the base and the scale) on
/// top of the base acting in them.
fn train_on<E: GoalEnv + 'static>(
    make: impl Fn() -> E,
    residual: Option<(Arc<Policy>, f64)>,
    config: DdpgHerConfig,
    options: &TrainOptions,
) -> anyhow::Result<dexcube_rl::train::Trained> {
    let Some((base, scale)) = residual else {
        return Ok(train(make, config, options)?);
    };
    // Checked once here, so that every environment after it is made alike.
    if let Err(message) = ResidualEnv::new(make(), base.clone(), scale) {
        bail!("cannot train a residual: {message}");
    }
    let wrapped = || {
        ResidualEnv::new(make(), base.clone(), scale)
            .unwrap_or_else(|message| unreachable!("checked above: {message}"))
    };
    Ok(train(wrapped, config, options)?)
}

pub fn run(args: TrainArgs) -> anyhow::Result<ExitCode> {
    let Workers {
        envs,
        threads,
        seed,
    } = args.workers;
    if envs == 0 || threads == 0 || args.epochs == 0 {
        bail!("--envs, --threads and --epochs must be at least 1");
    }
    if args.quarter_goals && matches!(args.choice.env, EnvKind::Rot) {
        bail!("--quarter-goals is for LayerOpEnv (train layer)");
    }
    let object = args.choice.object()?;
    let square = args.choice.square()?;
    let view = args.choice.view()?;
    if args.starts.is_some()
        && matches!(args.choice.env, EnvKind::Layer)
        && args.choice.layer_move != LayerMove::UPrime
    {
        bail!(
            "--starts for layer are the operator's Stage 2 starts: train them with --move \"U'\""
        );
    }
    if !(0.0..=1.0).contains(&args.start_share) {
        bail!(
            "--start-share must be between 0 and 1, not {}",
            args.start_share
        );
    }
    if !(args.failed_weight.is_finite() && args.failed_weight > 0.0) {
        bail!(
            "--failed-weight must be a positive number, not {}",
            args.failed_weight
        );
    }
    let rate = args.choice.control_rate;
    let suffix = args
        .choice
        .named_object()?
        .map(|object| format!("-{}", object.name()))
        .unwrap_or_default();
    let variant = match args.choice.env {
        EnvKind::Rot => args.choice.mode.name().to_string() + &suffix,
        EnvKind::Layer => {
            args.choice.layer_move.name().replace('\'', "p")
                + if args.quarter_goals { "-quarter" } else { "" }
                + &suffix
        }
    } + if square { "-square" } else { "" }
        + if args.choice.intact()? { "-intact" } else { "" }
        + if args.choice.turn_ends { "-ends" } else { "" }
        + if view.misalignment { "-seen" } else { "" }
        + if view.grip { "-grip" } else { "" }
        + &if rate == ControlRate::PAPER {
            String::new()
        } else {
            format!("-sub{rate}")
        }
        + if args.residual_of.is_some() {
            "-residual"
        } else {
            ""
        };
    let name = args.choice.env.name();
    let (out, resume) = match (&args.out, &args.resume) {
        (_, Some(dir)) => (dir.clone(), true),
        (Some(dir), None) => (dir.clone(), false),
        (None, None) => (
            PathBuf::from(format!("runs/{name}-{variant}-seed{}", seed)),
            false,
        ),
    };
    if resume {
        same_as_begun(&out, &args)?;
    }
    let published = DdpgHerConfig::default();
    let mut config = DdpgHerConfig {
        // Baselines' 1 - 1/T, T the episode's control steps: the same discount per simulated
        // second at any control rate.
        gamma: 1.0 - 1.0 / rate.episode_steps() as f64,
        batches_per_cycle: args.batches,
        her: !args.no_her,
        noise_eps: args.noise_eps.unwrap_or(published.noise_eps),
        random_eps: args.random_eps.unwrap_or(published.random_eps),
        actor_lr: args.actor_lr.unwrap_or(published.actor_lr),
        anchor: args.anchor,
        drop_cost: args.drop_cost,
        hidden: vec![usize::from(args.width); published.hidden.len()],
        ..published
    };
    if args.td3 {
        config = config.with_td3();
    }
    if !(config.actor_lr > 0.0 && config.actor_lr.is_finite()) {
        bail!(
            "--actor-lr must be a positive number, not {}",
            config.actor_lr
        );
    }
    if !(config.anchor >= 0.0 && config.anchor.is_finite()) {
        bail!("--anchor must be 0 or more, not {}", config.anchor);
    }
    if !(config.drop_cost >= 1.0 && config.drop_cost.is_finite()) {
        bail!(
            "--drop-cost must be 1 (the floor) or more, not {}",
            config.drop_cost
        );
    }
    if config.anchor > 0.0 && args.init.is_none() && args.init_actor.is_none() && !resume {
        bail!("--anchor holds the actor near the one it starts from: pass --init or --init-actor");
    }
    for (name, value) in [
        ("--noise-eps", config.noise_eps),
        ("--random-eps", config.random_eps),
    ] {
        if !(0.0..=1.0).contains(&value) {
            bail!("{name} must be between 0 and 1, not {value}");
        }
    }
    let options = TrainOptions {
        epochs: args.epochs,
        envs,
        threads,
        seed,
        out_dir: Some(out.clone()),
        resume,
        init_from: args.init.clone(),
        init_actor: args.init_actor.clone(),
        snapshot_every: args.snapshot_every,
        critic_only_epochs: args.critic_only_epochs,
        zero_output: args.residual_of.is_some(),
        progress: true,
        label: args.choice.name()?,
        metadata: serde_json::json!({
            "env": name,
            "variant": variant,
            "goals": if args.quarter_goals { "quarter turn" } else { "uniform" },
            "success": format!(
                "{}{}",
                match args.choice.env {
                    EnvKind::Rot => "pose",
                    EnvKind::Layer => "angle",
                },
                args.choice.success_suffix("cube ")?
            ),
            "observation": view.name().map_or("paper".to_string(), |name| format!("with the {name}")),
            "object": object.name(),
            "mode": matches!(args.choice.env, EnvKind::Rot).then(|| args.choice.mode.name()),
            "critic_only_epochs": args.critic_only_epochs,
            "init_actor": args.init_actor.as_ref().map(|p| p.display().to_string()),
            "starts": args.starts.as_ref().map(|p| p.display().to_string()),
            "start_share": args.starts.as_ref().map(|_| args.start_share),
            "failed_weight": args.starts.as_ref().map(|_| args.failed_weight),
            "control_substeps": rate.substeps(),
            "physics_spread": args.physics_spread,
            "angle_threshold": args.choice.angle_threshold,
            "residual": residual_setting(&args),
        }),
    };
    eprintln!(
        "training {} into {} (seed {})",
        options.label,
        out.display(),
        seed
    );
    let scene = Scene::load(object.scene())?;
    let starts = match &args.starts {
        Some(path) => Some(StartMix {
            starts: starts_for(path, &scene, args.choice.env)?.0,
            pick: StartPick::Share {
                share: args.start_share,
                failed_weight: args.failed_weight,
            },
        }),
        None => None,
    };
    let settings = EpisodeSettings {
        rate,
        physics_spread: args.physics_spread,
        ..EpisodeSettings::PAPER
    };
    if let Err(message) = check_scale(args.residual_scale) {
        bail!("--residual-scale: {message}");
    }
    let residual = match &args.residual_of {
        Some(base) => Some((
            Arc::new(Policy::load(base, &burn::prelude::Device::flex())?),
            args.residual_scale,
        )),
        None => None,
    };
    let trained = match args.choice.env {
        EnvKind::Rot => {
            let goal = args.choice.rot_goal()?;
            let make = || {
                CubeRotEnv::with_scene(scene.clone(), goal)
                    .with_view(view)
                    .with_starts(starts.clone())
                    .with_settings(settings)
            };
            train_on(make, residual, config, &options)?
        }
        EnvKind::Layer => {
            let (layer_move, goal) = (args.choice.layer_move, args.choice.layer_goal()?);
            let goals = if args.quarter_goals {
                LayerGoals::Evaluation
            } else {
                LayerGoals::Training
            };
            let make = || {
                LayerOpEnv::with_scene(scene.clone(), layer_move, goals)
                    .with_goal(goal)
                    .with_view(view)
                    .with_starts(starts.clone())
                    .with_settings(settings)
            };
            train_on(make, residual, config, &options)?
        }
    };
    let best = trained
        .metrics
        .iter()
        .map(|m| m.test_success)
        .fold(0.0, f64::max);
    eprintln!(
        "done: {} epochs, best test success {best:.2}; best policy in {}, curves in {}",
        trained.metrics.len(),
        out.join("best.safetensors").display(),
        out.join("success.png").display()
    );
    Ok(ExitCode::SUCCESS)
}
