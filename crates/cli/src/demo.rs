//! `dexcube demo`: the project's main job. The hand solves a scrambled cube with the shipped
//! policies: the plan is printed, each stage and rollback is narrated as it happens, and the
//! run ends solved or failed with its action number, optionally as a video.

use std::io::{self, IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use dexcube_cube::{DistanceTable, format_moves, scrambles_at_distance};
use dexcube_operator::eval::{Hooks, resting_point, run_cube};
use dexcube_operator::{Event, Failure, Planner};
use dexcube_sim::{Scene, SceneKind, Sim};

use crate::eval::{OperatorArgs, PolicyArgs};
use crate::net;
use crate::video::Video;

/// Scrambles a cube and has the hand solve it with the shipped policies.
#[derive(Args)]
pub struct DemoArgs {
    /// Move distance of the scramble, 1 to 14 quarter turns.
    #[arg(long, short, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=14))]
    distance: u8,
    /// Seed of the scramble and of the rollback's randomisations.
    #[arg(long, short, default_value_t = 0)]
    seed: u64,
    /// Write a video of the hand: .gif, or .mp4 with ffmpeg installed.
    #[arg(long)]
    video: Option<PathBuf>,
    /// Run the plan open loop, without the rollback mechanism.
    #[arg(long)]
    no_rollback: bool,
    #[command(flatten)]
    policies: PolicyArgs,
    #[command(flatten)]
    operator: OperatorArgs,
}

pub fn run(args: DemoArgs) -> anyhow::Result<ExitCode> {
    let files = args.policies.files()?;
    let colour = io::stdout().is_terminal();
    let table = DistanceTable::build();
    let scramble = scrambles_at_distance(&table, args.distance as usize, 1, args.seed)
        .pop()
        .expect("every distance from 1 to 14 has positions");
    let mut out = io::stdout().lock();
    writeln!(
        out,
        "Scrambled cube at move distance {} (seed {}): {}",
        args.distance, args.seed, scramble.facelets
    )?;
    write!(out, "{}", net::draw(&scramble.facelets, colour))?;
    writeln!(
        out,
        "Policies: Stage 1 {} ({} mode), Stage 2 {}; rollback {}",
        files.rot.display(),
        files.rot_mode.name(),
        files.layer.display(),
        if args.no_rollback { "off" } else { "on" }
    )?;
    let scene = Scene::load(SceneKind::Cube)?;
    let mut stages = files.load(resting_point()?)?;
    let mut video = match &args.video {
        Some(path) => Some(Video::new(path, &Sim::new(scene.clone()))?),
        None => None,
    };
    let mut watch = |sim: &mut Sim| {
        if let Some(video) = video.as_mut() {
            video.watch(sim);
        }
    };
    let distance = args.distance;
    let mut narrate = |event: &Event| {
        let line = match event {
            Event::Plan(plan) => format!(
                "Plan, {} quarter turns (optimal: {}): {}",
                plan.len(),
                distance,
                format_moves(plan)
            ),
            Event::Stage1 {
                face,
                landed,
                attempt,
                ok,
            } => {
                format!(
                    "  Stage 1: bring {face} up (attempt {attempt}) - {landed} up, {}",
                    if *ok { "pose reached" } else { "pose off" }
                )
            }
            Event::AlreadyUp(face) => format!("  Stage 1: not needed, {face} is already up"),
            Event::Stage2 { turn, of } => {
                format!("  Stage 2: U' on the top layer ({turn} of {of})")
            }
            Event::Randomised(why) => format!("  rollback: {why}"),
            Event::Stage1TurnedLayer => {
                "  rollback: Stage 1 turned a layer; Stage 2 skipped".to_string()
            }
            Event::Ended { stage, failure } => format!(
                "  Stage {stage} ended the attempt: {}",
                match failure {
                    Failure::Diverged => "the physics blew up",
                    _ => "the cube fell off the hand",
                }
            ),
            Event::MoveDone(m) => format!("move {m} done"),
            Event::Replan(plan) => format!(
                "  rollback: the move did not happen; new plan: {}",
                format_moves(plan)
            ),
        };
        let _ = writeln!(io::stdout(), "{line}");
    };
    drop(out);
    let hooks = Hooks {
        watch: &mut watch,
        narrate: &mut narrate,
        stage1_starts: None,
        stage2_starts: None,
    };
    let job = (
        scramble.moves.as_slice(),
        args.operator.config(!args.no_rollback),
        args.seed,
    );
    let hand_plans = args.operator.hand_plans();
    let planner = Planner {
        optimal: &table,
        any_length: hand_plans.as_ref(),
    };
    let outcome = run_cube(&mut stages, &scene, planner, job, hooks);
    let mut out = io::stdout().lock();
    match outcome.failure {
        None => writeln!(out, "Solved with {} atomic actions.", outcome.actions)?,
        Some(f) => writeln!(
            out,
            "Failed ({f:?}) after {} atomic actions.",
            outcome.actions
        )?,
    }
    writeln!(
        out,
        "({} randomisations, {} re-plans, {} control steps)",
        outcome.randomisations, outcome.replans, outcome.control_steps
    )?;
    if let Some(video) = video {
        video.save()?;
    }
    Ok(if outcome.solved {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
