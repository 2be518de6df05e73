//! `dexcube bench sim`: control steps per second of each scene under random actions, in
//! 100-step episodes, through `Sim` and through a raw `mj_step` loop on the same model in
//! the same run (the wrapper's overhead is their ratio), on one thread and on two.

use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

use clap::Args;
use dexcube_sim::{HAND_ACTUATORS, SUBSTEPS, Scene, SceneKind, Sim};
use mujoco_rs::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

#[derive(Args)]
pub struct SimArgs {
    /// Control steps timed per scene and per thread.
    #[arg(long, default_value_t = 1000)]
    steps: usize,
    /// Seed of the random actions.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Only these scenes (rot, layer, cube); all by default.
    #[arg(long, value_delimiter = ',')]
    scene: Vec<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct SceneSpeed {
    scene: &'static str,
    raw_steps_per_s: f64,
    sim_steps_per_s: f64,
    overhead: f64,
    two_threads_steps_per_s: f64,
    two_thread_scaling: f64,
    contacts_per_step: f64,
}

#[derive(Serialize)]
struct SimReport {
    steps: usize,
    seed: u64,
    /// Two threads over one on a pure arithmetic loop: what this machine's cores allow.
    machine_two_thread_scaling: f64,
    scenes: Vec<SceneSpeed>,
    cube_over_rot: f64,
}

/// Episode length in control steps, as the environments use.
pub const EPISODE: usize = dexcube_env::EPISODE_STEPS;

/// Interleaved timing rounds of the raw loop and the wrapper.
const ROUNDS: usize = 3;

/// Random actions for `steps` control steps, the same for every run.
pub fn actions(steps: usize, seed: u64) -> Vec<[f64; HAND_ACTUATORS]> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..steps)
        .map(|_| std::array::from_fn(|_| rng.random_range(-1.0..=1.0)))
        .collect()
}

/// Steps per second through the `Sim` wrapper, and contacts per step.
pub fn through_sim(scene: &Arc<Scene>, actions: &[[f64; HAND_ACTUATORS]]) -> (f64, f64) {
    let mut sim = Sim::new(scene.clone());
    let mut contacts = 0;
    let start = Instant::now();
    for (i, action) in actions.iter().enumerate() {
        if i % EPISODE == 0 {
            sim.reset();
        }
        sim.set_action(action);
        if sim.step().is_err() {
            sim.reset();
        }
        contacts += sim.data().ffi().ncon as usize;
    }
    (
        actions.len() as f64 / start.elapsed().as_secs_f64(),
        contacts as f64 / actions.len() as f64,
    )
}

/// Steps per second of a bare loop: controls written straight into `MjData`, `mj_step`
/// called `SUBSTEPS` times, nothing else. (In the cube scene `Sim` also applies the cubelets'
/// detent, part of the cube's mechanics, so the two runs follow slightly different paths.)
fn raw_loop(scene: &Arc<Scene>, actions: &[[f64; HAND_ACTUATORS]]) -> f64 {
    let mut data = MjData::new(scene.model().clone());
    let mut ctrl = [0.0; HAND_ACTUATORS];
    let start = Instant::now();
    for (i, action) in actions.iter().enumerate() {
        if i % EPISODE == 0 {
            data.reset();
            data.forward();
        }
        scene.action_to_ctrl(action, &mut ctrl);
        data.ctrl_mut()[..HAND_ACTUATORS].copy_from_slice(&ctrl);
        for _ in 0..SUBSTEPS {
            data.step();
        }
    }
    actions.len() as f64 / start.elapsed().as_secs_f64()
}

/// How much faster two threads run a pure arithmetic loop than one: the most a CPU-bound
/// program can scale on this machine right now (vCPUs may share physical cores).
pub fn machine_scaling() -> f64 {
    fn spin() -> f64 {
        let mut x = 1.0f64;
        for i in 0..60_000_000u64 {
            x = x.mul_add(1.000_000_1, (i & 7) as f64 * 1e-9);
        }
        x
    }
    let start = Instant::now();
    std::hint::black_box(spin());
    let one = start.elapsed().as_secs_f64();
    let start = Instant::now();
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| std::hint::black_box(spin()));
        }
    });
    2.0 * one / start.elapsed().as_secs_f64()
}

/// Total steps per second of two threads, each with its own `Sim`.
fn two_threads(scene: &Arc<Scene>, actions: &[[f64; HAND_ACTUATORS]]) -> f64 {
    let start = Instant::now();
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| through_sim(scene, actions));
        }
    });
    2.0 * actions.len() as f64 / start.elapsed().as_secs_f64()
}

pub fn run(args: SimArgs) -> anyhow::Result<ExitCode> {
    let actions = actions(args.steps, args.seed);
    let machine_two_thread_scaling = machine_scaling();
    let mut scenes = Vec::new();
    let wanted =
        |kind: &SceneKind| args.scene.is_empty() || args.scene.iter().any(|s| s == kind.name());
    for kind in SceneKind::ALL.into_iter().filter(wanted) {
        let scene = Scene::load(kind)?;
        // Warm up, then interleave rounds so drift hits both alike, and keep each one's best:
        // on a noisy machine the fastest round is the one least disturbed.
        through_sim(&scene, &actions[..args.steps.min(100)]);
        let (mut raw, mut sim, mut contacts) = (0.0f64, 0.0f64, 0.0);
        for _ in 0..ROUNDS {
            raw = raw.max(raw_loop(&scene, &actions));
            let (rate, per_step) = through_sim(&scene, &actions);
            (sim, contacts) = (sim.max(rate), per_step);
        }
        let two = two_threads(&scene, &actions);
        scenes.push(SceneSpeed {
            scene: kind.name(),
            raw_steps_per_s: raw,
            sim_steps_per_s: sim,
            overhead: raw / sim - 1.0,
            two_threads_steps_per_s: two,
            two_thread_scaling: two / sim,
            contacts_per_step: contacts,
        });
    }
    let rate = |name: &str| {
        scenes
            .iter()
            .find(|s| s.scene == name)
            .map_or(f64::NAN, |s| s.sim_steps_per_s)
    };
    let report = SimReport {
        steps: args.steps,
        seed: args.seed,
        machine_two_thread_scaling,
        cube_over_rot: rate("cube") / rate("rot"),
        scenes,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(ExitCode::SUCCESS);
    }
    println!(
        "dexcube bench sim --steps {} --seed {} ({} substeps of 0.002 s per control step, random actions, {}-step episodes)",
        report.steps, report.seed, SUBSTEPS, EPISODE
    );
    println!("scene   raw mj_step/s  Sim steps/s  overhead  2 threads/s  scaling  contacts/step");
    for s in &report.scenes {
        println!(
            "{:<6}  {:>13.0}  {:>11.0}  {:>7.1}%  {:>11.0}  {:>6.2}x  {:>13.1}",
            s.scene,
            s.raw_steps_per_s,
            s.sim_steps_per_s,
            100.0 * s.overhead,
            s.two_threads_steps_per_s,
            s.two_thread_scaling,
            s.contacts_per_step
        );
    }
    println!("cube / rot: {:.2}", report.cube_over_rot);
    println!(
        "this machine's own 2-thread scaling on pure arithmetic, same run: {:.2}x",
        report.machine_two_thread_scaling
    );
    Ok(ExitCode::SUCCESS)
}
