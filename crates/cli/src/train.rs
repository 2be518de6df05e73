//! `dexcube train`: a skill trained by a recipe (see [`crate::recipe`]), with a progress bar,
//! one metrics CSV and curves over the whole recipe, checkpoints every epoch and exact resume;
//! and the commands that draw runs' curves and make policies of trained ones.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::bail;
use clap::Args;
use dexcube_env::GoalLead;
use dexcube_rl::Policy;
use dexcube_rl::checkpoint::CheckpointError;
use dexcube_rl::handover::{FarHandover, Handover};
use dexcube_rl::recipe::{RecipeRun, run_recipe};
use dexcube_rl::start_gesture::StartGesture;
use dexcube_rl::start_route::{RoutedEpisodes, StartRoute};

use crate::env::{EnvKind, angle_flag};
use crate::recipe::{PhaseEnv, RecipeFile};

/// How `bench rl` collects experience. Eight environments on two threads balance physics
/// against the 40 batches of a cycle on a 2-core machine.
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

/// Trains a skill from random weights by a recipe: every phase it needs, in one run that moves
/// from phase to phase by rules read from its own test success (`dexcube train rot
/// --print-recipe` shows them). Writes DIR/policy (the skill's policy), DIR/metrics.csv and
/// curves against env steps and hours, and each phase's run under DIR/phases; a run stopped at
/// any moment goes on with `--resume DIR`.
#[derive(Args)]
pub struct TrainArgs {
    /// The skill: rot (Stage 1, CubeRotEnv) or layer (Stage 2, LayerOpEnv).
    #[arg(value_enum, required_unless_present = "resume")]
    skill: Option<EnvKind>,
    /// The recipe: dexcube (ours), paper (DDPG + HER at the paper's settings, in one phase),
    /// or the path of a JSON file of one.
    #[arg(long, default_value = "dexcube")]
    recipe: String,
    /// Print the recipe as JSON and exit, a start for a recipe of your own.
    #[arg(long)]
    print_recipe: bool,
    /// Seed of everything random: weights, episodes, exploration.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output folder (default: runs/<skill>-<recipe>-seed<seed>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Go on with the run in this folder where it stopped; its recipe, skill and seed are
    /// the ones it began with.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["skill", "out", "print_recipe"])]
    resume: Option<PathBuf>,
    /// Threads stepping the environments.
    #[arg(long, default_value_t = 2)]
    threads: usize,
}

/// The file in a recipe's run folder that says what it runs.
const RECIPE_FILE: &str = "recipe.json";

pub fn run(args: TrainArgs) -> anyhow::Result<ExitCode> {
    if args.threads == 0 {
        bail!("--threads must be at least 1");
    }
    let (dir, file) = match (&args.resume, args.skill) {
        (Some(dir), _) => {
            let path = dir.join(RECIPE_FILE);
            if !path.is_file() {
                bail!(
                    "{} holds no recipe's run (no {RECIPE_FILE}): pass the folder `dexcube train --out` wrote",
                    dir.display()
                );
            }
            let text = std::fs::read_to_string(&path)?;
            let file: RecipeFile = serde_json::from_str(&text).map_err(|e| {
                anyhow::anyhow!(
                    "{} is not a recipe's run file ({e}); it may be damaged: restore it or train again",
                    path.display()
                )
            })?;
            (dir.clone(), file)
        }
        (None, Some(skill)) => {
            let recipe = crate::recipe::named(&args.recipe, skill)?;
            if args.print_recipe {
                println!("{}", serde_json::to_string_pretty(&recipe)?);
                return Ok(ExitCode::SUCCESS);
            }
            recipe.check().map_err(anyhow::Error::msg)?;
            let dir = args.out.clone().unwrap_or_else(|| {
                let name = Path::new(&args.recipe)
                    .file_stem()
                    .map_or("recipe".into(), |s| s.to_string_lossy().into_owned());
                PathBuf::from(format!("runs/{}-{name}-seed{}", skill.name(), args.seed))
            });
            if dir.join(RECIPE_FILE).exists() {
                bail!(
                    "{} holds a run already: go on with `dexcube train --resume {}`, or choose \
                     another --out",
                    dir.display(),
                    dir.display()
                );
            }
            let file = RecipeFile {
                skill: skill.name().to_string(),
                seed: args.seed,
                recipe,
            };
            dexcube_rl::checkpoint::save_json(&dir.join(RECIPE_FILE), &file)?;
            (dir, file)
        }
        (None, None) => bail!("name the skill to train (rot or layer), or --resume DIR"),
    };
    let skill = file.skill()?;
    eprintln!(
        "training {} by the recipe '{}' ({} phases) into {} (seed {})",
        skill.stage(),
        file.recipe.name,
        file.recipe.phases.len(),
        dir.display(),
        file.seed
    );
    let run = RecipeRun {
        dir: dir.clone(),
        seed: file.seed,
        threads: args.threads,
        progress: true,
    };
    let outcome = run_recipe(&file.recipe, &run, |env: &PhaseEnv| {
        crate::recipe::phase_envs(env, skill).map_err(|e| format!("{e:#}"))
    })?;
    let last = outcome.metrics.last();
    eprintln!(
        "done: {} epochs, {} env steps, {:.2} h; the policy is {}, the curves {} and {}",
        outcome.metrics.len(),
        last.map_or(0, |e| e.env_steps),
        last.map_or(0.0, |e| e.wall_s / 3600.0),
        outcome.policy.display(),
        dir.join("success.png").display(),
        dir.join("success-hours.png").display()
    );
    Ok(ExitCode::SUCCESS)
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
