//! `dexcube bench rl`: the learner's costs. Time per optimisation batch (batch 256, 3x256
//! actor and critic, Adam, polyak), with the late steps over the early ones as the guard
//! against autodiff history growing in the target updates; time per batch-1 actor inference;
//! and, from a short real training run on CubeRotEnv, environment steps per second and the
//! shares of time in physics, learning and the rest.

use std::process::ExitCode;
use std::time::{Duration, Instant};

use burn::prelude::Device;
use clap::Args;
use dexcube_env::{CubeRotEnv, RotGoal, RotMode};
use dexcube_rl::agent::Batch;
use dexcube_rl::{Agent, DdpgHerConfig, Dims, Learners, TrainOptions, train};
use dexcube_sim::{Scene, SceneKind};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[derive(Args)]
pub struct RlArgs {
    /// Optimisation steps timed.
    #[arg(long, default_value_t = 300)]
    updates: usize,
    #[command(flatten)]
    workers: crate::train::Workers,
}

fn median(mut xs: Vec<Duration>) -> Duration {
    xs.sort();
    xs[xs.len() / 2]
}

pub fn run(args: RlArgs) -> anyhow::Result<ExitCode> {
    let crate::train::Workers {
        envs,
        threads,
        seed,
    } = args.workers;
    let dims = Dims {
        observation: 61,
        goal: 7,
        action: 20,
    };
    let config = DdpgHerConfig::default();
    let mut agent = Agent::new(dims, config.clone(), &Device::flex(), seed);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut random =
        |n: usize| -> Vec<f64> { (0..n).map(|_| rng.random_range(-1.0..1.0)).collect() };
    let b = config.batch_size;
    let batch = Batch {
        len: b,
        observation: random(b * dims.observation),
        goal: random(b * dims.goal),
        action: random(b * dims.action)
            .into_iter()
            .map(|x| x as f32)
            .collect(),
        reward: random(b)
            .into_iter()
            .map(|x| if x > 0.0 { -1.0 } else { 0.0 })
            .collect(),
        next_observation: random(b * dims.observation),
        terminal: vec![0.0; b],
    };
    let mut times = Vec::with_capacity(args.updates);
    for i in 0..args.updates {
        let start = Instant::now();
        agent.train(&batch, Learners::ActorAndCritic);
        if i % config.batches_per_cycle == config.batches_per_cycle - 1 {
            agent.end_cycle();
        }
        times.push(start.elapsed());
    }
    let window = (args.updates / 6).max(1);
    let early = median(times[..window].to_vec());
    let late = median(times[times.len() - window..].to_vec());
    let single = random(dims.observation);
    let goal = random(dims.goal);
    let mut inference = Vec::with_capacity(1000);
    for _ in 0..1000 {
        let start = Instant::now();
        std::hint::black_box(agent.act(&single, &goal, 1, None));
        inference.push(start.elapsed());
    }
    println!(
        "dexcube bench rl --updates {} --envs {} --threads {} --seed {}",
        args.updates, envs, threads, seed
    );
    println!(
        "optimisation batch (256, 3x256 actor and critic, Adam): median {:.1} ms",
        late.as_secs_f64() * 1e3
    );
    println!(
        "  first {window} vs last {window} updates: {:.1} ms vs {:.1} ms (ratio {:.2}; flat means no graph growth)",
        early.as_secs_f64() * 1e3,
        late.as_secs_f64() * 1e3,
        late.as_secs_f64() / early.as_secs_f64()
    );
    println!(
        "batch-1 actor inference: median {:.1} µs",
        median(inference).as_secs_f64() * 1e6
    );

    let scene = Scene::load(SceneKind::Rot)?;
    let short = DdpgHerConfig {
        cycles_per_epoch: 5,
        test_episodes: envs,
        ..config
    };
    let options = TrainOptions::in_memory("bench", 1, envs, threads, seed);
    let trained = train(
        || CubeRotEnv::with_scene(scene.clone(), RotGoal::paper(RotMode::Paper)),
        short,
        &options,
    )?;
    let m = &trained.metrics[0];
    let total = m.rollout_s + m.learning_s + m.other_s;
    println!(
        "training CubeRotEnv, 5 cycles of {} episodes and 40 batches: {:.0} env steps/s; time in physics and acting {:.0}%, learning {:.0}%, other {:.0}%",
        envs,
        m.env_steps_per_s,
        100.0 * m.rollout_s / total,
        100.0 * m.learning_s / total,
        100.0 * m.other_s / total
    );
    Ok(ExitCode::SUCCESS)
}
