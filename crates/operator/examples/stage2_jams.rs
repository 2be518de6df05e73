//! How Stage 2 moves when it jams, and where it stands once jammed. Runs a Stage 2 policy
//! from fresh placements (episode i reset with seed + i, as `dexcube eval-stage` does) or
//! from the failed starts of a recording, and sorts the episodes by how they ended: success;
//! a jam (the layer never turned, the cube left out of its good state); any other miss. For
//! each kind it prints how much the fingers' targets changed per step, over the first steps
//! and after them.
//!
//! `--slew S` caps each actuator's target change per control step
//! ([`EpisodeSettings::action_slew`]), to ask whether gentler fingers jam less. `--keep-jams
//! OUT` writes, for every jammed episode, the physics state at steps 10, 30 and 60 as Stage 2
//! starts (the quarter turn asked for, counted from the angle the layer had turned, marked
//! failed), so that a run can train from inside a jam (a recipe phase of `dexcube train layer` with `starts` OUT).
//! `--steps N` runs each episode for N control steps instead of the paper's 100, sorts it by
//! how it stands at step N, and counts the episodes that step 100 judged otherwise: whether
//! more time would turn the layers Stage 2 leaves unturned.
//!
//! `cargo run --release -p dexcube-operator --example stage2_jams -- POLICY
//! (--fresh SEED EPISODES | --failed-starts FILE) [--slew S] [--keep-jams OUT] [--steps N]`

use std::path::{Path, PathBuf};

use dexcube_env::layer::LayerGoals;
use dexcube_env::{
    EpisodeSettings, GoalEnv, LayerMove, LayerOpEnv, RecordedFailure, RecordedStart, SimulatedEnv,
    is_square,
};
use dexcube_operator::stages::PolicyStage2;
use dexcube_rl::Policy;
use dexcube_rl::start_file::{StartsOrigin, load_starts, save_starts};
use dexcube_sim::{Scene, SceneKind};

/// A layer more than this short of the quarter turn never turned (67.5 degrees, as
/// `eval-stage` counts).
const NEVER_TURNED: f64 = 3.0 * std::f64::consts::FRAC_PI_8;
/// The first steps, where session 3 saw the side layers give way.
const EARLY_STEPS: usize = 5;
/// The steps of a jammed episode whose states `--keep-jams` writes.
const KEPT_STEPS: [usize; 3] = [10, 30, 60];

/// The episodes of one ending, and their mean action change per step and actuator.
#[derive(Default)]
struct Tally {
    episodes: usize,
    early_change: f64,
    late_change: f64,
}

impl Tally {
    fn line(&self, name: &str) -> String {
        let n = self.episodes.max(1) as f64;
        format!(
            "{name}: {} episodes; mean |action change| per step and actuator {:.3} over the \
             first {EARLY_STEPS} steps, {:.3} after",
            self.episodes,
            self.early_change / n,
            self.late_change / n,
        )
    }
}

/// Where the episodes begin.
enum Starts {
    Fresh { seed: u64, episodes: u64 },
    Failed(Vec<RecordedStart>),
}

struct Args {
    policy: PathBuf,
    starts: Starts,
    slew: Option<f64>,
    keep_jams: Option<PathBuf>,
    steps: usize,
}

fn parse_args() -> Result<Args, Box<dyn std::error::Error>> {
    let usage = "usage: stage2_jams POLICY (--fresh SEED EPISODES | --failed-starts FILE) \
                 [--slew S] [--keep-jams OUT] [--steps N]";
    let args: Vec<String> = std::env::args().skip(1).collect();
    let policy = PathBuf::from(args.first().ok_or(usage)?);
    let (mut starts, mut slew, mut keep_jams) = (None, None, None);
    let mut steps = dexcube_env::EPISODE_STEPS;
    let mut rest = args[1..].iter();
    while let Some(flag) = rest.next() {
        let mut value = || rest.next().ok_or(usage);
        match flag.as_str() {
            "--fresh" => {
                let (seed, episodes) = (value()?.parse()?, value()?.parse()?);
                starts = Some(Starts::Fresh { seed, episodes });
            }
            "--failed-starts" => {
                let (recorded, _) = load_starts(Path::new(value()?))?;
                starts = Some(Starts::Failed(
                    recorded.into_iter().filter(|s| s.failed).collect(),
                ));
            }
            "--slew" => slew = Some(value()?.parse()?),
            "--keep-jams" => keep_jams = Some(PathBuf::from(value()?)),
            "--steps" => {
                steps = value()?.parse()?;
                if steps < dexcube_env::EPISODE_STEPS {
                    return Err(format!(
                        "--steps {steps}: give at least the paper's {} steps, which it \
                         compares with",
                        dexcube_env::EPISODE_STEPS
                    )
                    .into());
                }
            }
            _ => return Err(usage.into()),
        }
    }
    Ok(Args {
        policy,
        starts: starts.ok_or(usage)?,
        slew,
        keep_jams,
        steps,
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = parse_args()?;
    let policy = Policy::load(&args.policy, &burn::prelude::Device::flex())?;
    let mut env = LayerOpEnv::with_scene(
        Scene::load(SceneKind::Cube)?,
        LayerMove::UPrime,
        LayerGoals::Evaluation,
    )
    .with_goal(PolicyStage2::trained_goal(&policy, &args.policy)?)
    .with_view(PolicyStage2::trained_view(&policy, &args.policy)?)
    .with_settings(EpisodeSettings {
        action_slew: args.slew,
        ..EpisodeSettings::PAPER
    });
    let episodes = match &args.starts {
        Starts::Fresh { episodes, .. } => *episodes as usize,
        Starts::Failed(starts) => starts.len(),
    };
    let [mut succeeded, mut jammed, mut other]: [Tally; 3] = Default::default();
    let mut jam_states = Vec::new();
    // Episodes that step 100 judged a success and step N did not, and the other way round.
    let (mut lost_later, mut won_later) = (0, 0);
    for episode in 0..episodes {
        let (mut observation, _) = match &args.starts {
            Starts::Fresh { seed, .. } => env.reset(Some(seed + episode as u64)),
            Starts::Failed(starts) => env.reset_from(&starts[episode])?,
        };
        let (mut changes, mut kept) = (Vec::new(), Vec::new());
        let mut previous: Option<Vec<f64>> = None;
        let mut step = 0;
        let mut success_at_paper_end = false;
        let info = loop {
            if KEPT_STEPS.contains(&step) {
                kept.push(RecordedStart {
                    failed: true,
                    ..env.fresh_start()
                });
            }
            let action = policy.act(&observation.observation, &observation.desired_goal);
            if let Some(before) = &previous {
                let moved: f64 = action.iter().zip(before).map(|(a, b)| (a - b).abs()).sum();
                changes.push(moved / action.len() as f64);
            }
            let transition = env.step(&action);
            step += 1;
            previous = Some(action);
            observation = transition.observation;
            if step == dexcube_env::EPISODE_STEPS {
                success_at_paper_end = transition.info.is_success;
            }
            if transition.terminated || step >= args.steps {
                break transition.info;
            }
        };
        match (success_at_paper_end, info.is_success) {
            (true, false) => lost_later += 1,
            (false, true) => won_later += 1,
            _ => {}
        }
        let tally = if info.is_success {
            &mut succeeded
        } else if !is_square(env.sim()) && !info.dropped && info.angle_error > NEVER_TURNED {
            jam_states.extend(kept);
            &mut jammed
        } else {
            &mut other
        };
        let mean = |steps: &[f64]| steps.iter().sum::<f64>() / steps.len().max(1) as f64;
        let early = changes.len().min(EARLY_STEPS - 1);
        tally.episodes += 1;
        tally.early_change += mean(&changes[..early]);
        tally.late_change += mean(&changes[early..]);
    }
    println!(
        "policy {}, slew limit {:?}, {} steps an episode",
        args.policy.display(),
        args.slew,
        args.steps
    );
    println!("{}", succeeded.line("succeeded"));
    println!("{}", jammed.line("jammed (never turned, left skewed)"));
    println!("{}", other.line("missed otherwise"));
    if args.steps != dexcube_env::EPISODE_STEPS {
        println!(
            "against step {}: {won_later} failed there and succeeded at step {}, {lost_later} \
             the other way round",
            dexcube_env::EPISODE_STEPS,
            args.steps
        );
    }
    if let Some(out) = &args.keep_jams {
        let origin = StartsOrigin {
            stage: "layer".into(),
            failure: RecordedFailure::NotSquare,
            scene: "cube".into(),
            command: std::env::args().collect::<Vec<_>>().join(" "),
        };
        save_starts(out, &jam_states, &origin)?;
        println!(
            "kept {} states from inside jams in {}",
            jam_states.len(),
            out.display()
        );
    }
    Ok(())
}
