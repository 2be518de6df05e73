//! `dexcube bench env`: environment steps per second, through `VecEnv` on 1, 2 and all
//! threads (one environment per thread), beside the bare simulator stepping the same scene
//! with the same actions in the same run; their ratio is the environments' overhead.

use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

use clap::Args;
use dexcube_env::layer::LayerGoals;
use dexcube_env::{CubeRotEnv, LayerMove, LayerOpEnv, RotGoal, RotMode, SimulatedEnv, VecEnv};
use dexcube_sim::{Scene, SceneKind};
use serde::Serialize;

use crate::bench_sim::{actions, machine_scaling, through_sim};

#[derive(Args)]
pub struct EnvArgs {
    /// Control steps timed per environment.
    #[arg(long, default_value_t = 1000)]
    steps: usize,
    /// Seed of the random actions and of the environments.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct EnvSpeed {
    env: &'static str,
    sim_steps_per_s: f64,
    /// (threads, environment steps per second), one environment per thread.
    threads: Vec<(usize, f64)>,
    /// Physics control steps per environment step: resets let the object settle.
    physics_per_env_step: f64,
    /// On one thread, wall time outside `Sim::step` over wall time inside it.
    overhead: f64,
}

/// Environment steps per second of `threads` environments on `threads` threads, the physics
/// control steps run per environment step, and the time outside the physics over the time in
/// it (for one thread, the environments' overhead).
fn vec_env_rate<E: SimulatedEnv>(
    make: impl Fn() -> E,
    threads: usize,
    steps: usize,
    seed: u64,
) -> (f64, f64, f64) {
    let mut vec_env = VecEnv::new((0..threads).map(|_| make()).collect(), threads);
    let actions: Vec<Vec<Vec<f64>>> = actions(steps, seed)
        .into_iter()
        .map(|a| vec![a.to_vec(); threads])
        .collect();
    vec_env.reset(seed);
    let physics = |v: &VecEnv<E>| {
        v.envs()
            .iter()
            .map(|e| e.sim().control_steps())
            .sum::<u64>()
    };
    let physics_time = |v: &VecEnv<E>| {
        v.envs()
            .iter()
            .map(|e| e.sim().physics_time().as_secs_f64())
            .sum::<f64>()
    };
    let (before, time_before) = (physics(&vec_env), physics_time(&vec_env));
    let start = Instant::now();
    for step_actions in &actions {
        vec_env.step(step_actions);
    }
    let wall = start.elapsed().as_secs_f64();
    let inside = (physics_time(&vec_env) - time_before) / threads as f64;
    let rate = (steps * threads) as f64 / wall;
    (
        rate,
        (physics(&vec_env) - before) as f64 / (steps * threads) as f64,
        wall / inside - 1.0,
    )
}

fn measure<E: SimulatedEnv>(
    name: &'static str,
    scene: &Arc<Scene>,
    make: impl Fn() -> E,
    args: &EnvArgs,
) -> EnvSpeed {
    let all = std::thread::available_parallelism().map_or(2, |n| n.get());
    let mut counts = vec![1, 2, all];
    counts.sort();
    counts.dedup();
    let (mut sim, mut threads, mut physics, mut overhead) = (0.0f64, vec![], 1.0, f64::INFINITY);
    for &n in &counts {
        let mut best = 0.0f64;
        for _ in 0..2 {
            if n == 1 {
                sim = sim.max(through_sim(scene, &actions(args.steps, args.seed)).0);
            }
            let (rate, per_step, outside) = vec_env_rate(&make, n, args.steps, args.seed);
            best = best.max(rate);
            physics = per_step;
            if n == 1 {
                overhead = overhead.min(outside);
            }
        }
        threads.push((n, best));
    }
    EnvSpeed {
        env: name,
        sim_steps_per_s: sim,
        threads,
        physics_per_env_step: physics,
        overhead,
    }
}

pub fn run(args: EnvArgs) -> anyhow::Result<ExitCode> {
    let rot_scene = Scene::load(SceneKind::Rot)?;
    let layer_scene = Scene::load(SceneKind::Layer)?;
    let reports = [
        measure(
            "CubeRotEnv",
            &rot_scene,
            || CubeRotEnv::with_scene(rot_scene.clone(), RotGoal::paper(RotMode::Paper)),
            &args,
        ),
        measure(
            "LayerOpEnv",
            &layer_scene,
            || LayerOpEnv::with_scene(layer_scene.clone(), LayerMove::UPrime, LayerGoals::Training),
            &args,
        ),
    ];
    let machine = machine_scaling();
    if args.json {
        let json = serde_json::json!({ "steps": args.steps, "seed": args.seed, "envs": reports, "machine_two_thread_scaling": machine });
        println!("{}", serde_json::to_string_pretty(&json)?);
        return Ok(ExitCode::SUCCESS);
    }
    println!(
        "dexcube bench env --steps {} --seed {} (random actions; resets counted in)",
        args.steps, args.seed
    );
    for r in &reports {
        let per_thread: Vec<String> = r
            .threads
            .iter()
            .map(|(n, rate)| format!("{n} thread(s) {rate:.0}/s"))
            .collect();
        println!(
            "{:<10}  bare Sim {:.0}/s  {}  ({:.2} physics steps per env step)  env overhead {:.1}% (time outside Sim::step over time inside)",
            r.env,
            r.sim_steps_per_s,
            per_thread.join(", "),
            r.physics_per_env_step,
            100.0 * r.overhead
        );
    }
    println!("this machine's own 2-thread scaling on pure arithmetic, same run: {machine:.2}x");
    Ok(ExitCode::SUCCESS)
}
