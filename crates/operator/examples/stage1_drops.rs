//! How Stage 1 drops the cube, replayed from the starts the operator recorded
//! (`dexcube eval --record-starts`): each start runs its 100-step episode with a Stage 1
//! policy (acting as its card says: goal lead, handover), and the cube's place on the palm is
//! followed step by step. It prints, for each radius, how many runs let the cube stray that
//! far across the palm from its resting point, among those that dropped it and those that kept
//! it, and how many steps before the drop the dropping runs first strayed. With a radius and a
//! step count it also runs the steadying reflex (`--steady-radius`, `--steady-steps` of
//! `dexcube eval`): the hand holds the neutral action for that many steps whenever the cube
//! strays past the radius.
//!
//! `cargo run --release -p dexcube-operator --example stage1_drops -- STARTS [RADIUS STEPS]
//! [--dropped-only] [--policy PREFIX]` (policy default `models/rot`, judged in pair mode).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use dexcube_env::{CubeRotEnv, GoalEnv, RotMode, SimulatedEnv, StartMix, StartPick};
use dexcube_operator::stages::{
    PolicyStage1, Steadier, Steadying, distance_across_palm, steadied_action,
};
use dexcube_rl::Policy;
use dexcube_sim::{Scene, SceneKind};

const RADII: [f64; 4] = [0.02, 0.03, 0.04, 0.05];

/// One replayed start: the first step the cube strayed past each radius, the step it dropped
/// at, and whether the policy's own success test passed at the episode's end (for a policy
/// trained with `--square`, as `models/rot` is, the pose in the good state).
struct Replay {
    strayed_at: [Option<usize>; RADII.len()],
    dropped_at: Option<usize>,
    reached: bool,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dropped_only = args.iter().any(|a| a == "--dropped-only");
    let policy_at = args.iter().position(|a| a == "--policy");
    let prefix = policy_at.map_or(PathBuf::from("models/rot"), |i| PathBuf::from(&args[i + 1]));
    let positional: Vec<&String> = args
        .iter()
        .enumerate()
        .filter(|&(i, a)| !a.starts_with("--") && policy_at.is_none_or(|p| i != p + 1))
        .map(|(_, a)| a)
        .collect();
    let Some(path) = positional.first() else {
        return Err(
            "usage: stage1_drops STARTS [RADIUS STEPS] [--dropped-only] [--policy PREFIX]".into(),
        );
    };
    let steadying = match positional.get(1..3) {
        Some([radius, steps]) => Some(Steadying {
            radius: radius.parse()?,
            steps: steps.parse()?,
        }),
        _ => None,
    };
    let (starts, origin) = dexcube_rl::start_file::load_starts(Path::new(path.as_str()))?;
    let starts: Arc<[_]> = starts.into();
    let policy = Policy::load(&prefix, &burn::prelude::Device::flex())?;
    let goal = PolicyStage1::trained_goal(&policy, RotMode::Pair, &prefix)?;
    let mut env = CubeRotEnv::with_scene(Scene::load(SceneKind::Cube)?, goal)
        .with_view(PolicyStage1::trained_view(&policy, &prefix)?)
        .with_starts(Some(StartMix {
            starts: starts.clone(),
            pick: StartPick::Numbered,
        }));
    let centre = env.resting_point();
    println!("{} starts from `{}`", starts.len(), origin.command);

    let mut replays = Vec::new();
    for (k, start) in starts.iter().enumerate() {
        if dropped_only && !start.failed {
            continue;
        }
        let (mut observation, _) = env.reset(Some(k as u64));
        let test = env.goal();
        // The policy acts as its card says (goal lead, handover), as in `eval-stage`.
        let mut acting = policy.episode();
        let mut steadier = steadying.map(|s| Steadier::new(s, centre));
        let mut replay = Replay {
            strayed_at: [None; RADII.len()],
            dropped_at: None,
            reached: false,
        };
        for step in 0..dexcube_env::EPISODE_STEPS {
            let off = distance_across_palm(env.sim(), centre);
            for (first, radius) in replay.strayed_at.iter_mut().zip(RADII) {
                if off > radius && first.is_none() {
                    *first = Some(step);
                }
            }
            let action = steadied_action(steadier.as_mut(), env.sim(), || {
                let achieved = || observation.achieved_goal.clone();
                let (seen, desired) = (&observation.observation, &observation.desired_goal);
                acting.act_toward(seen, desired, achieved, test.as_ref())
            });
            let transition = env.step(&action);
            replay.reached = transition.info.is_success;
            observation = transition.observation;
            if transition.info.dropped {
                replay.dropped_at = Some(step);
            }
            if transition.terminated {
                break;
            }
        }
        replays.push(replay);
    }

    let (dropping, keeping): (Vec<&Replay>, Vec<&Replay>) =
        replays.iter().partition(|r| r.dropped_at.is_some());
    let reached = replays.iter().filter(|r| r.reached).count();
    println!(
        "{} runs{}: {} dropped the cube, {reached} met the policy's success test at the episode's end",
        replays.len(),
        steadying.map_or(String::new(), |s| format!(
            ", holding still {} steps past {} m",
            s.steps, s.radius
        )),
        dropping.len()
    );
    for (i, radius) in RADII.iter().enumerate() {
        let mut leads: Vec<usize> = dropping
            .iter()
            .filter_map(|r| Some(r.dropped_at? - r.strayed_at[i]?))
            .collect();
        leads.sort_unstable();
        let kept_strayed = keeping.iter().filter(|r| r.strayed_at[i].is_some()).count();
        println!(
            "  strayed past {radius} m: {} of {} dropping runs (steps before the drop: {leads:?}), {kept_strayed} of {} runs that kept the cube",
            leads.len(),
            dropping.len(),
            keeping.len()
        );
    }
    Ok(())
}
