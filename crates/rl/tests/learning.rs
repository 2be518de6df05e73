//! Proof that the learner learns, before spending hours on the hand: DDPG + HER on the point
//! mass, against the same budget without HER, and TD3 + HER on the same budget.

use dexcube_rl::point_mass::PointMassEnv;
use dexcube_rl::{DdpgHerConfig, EpochMetrics, TrainOptions, train};

/// The baselines schedule shortened to fit a test: 10 cycles of 2 episodes and 40 batches per
/// epoch, 64-unit layers, everything else at the HER baselines' defaults.
fn small_config(her: bool) -> DdpgHerConfig {
    DdpgHerConfig {
        hidden: vec![64, 64, 64],
        cycles_per_epoch: 10,
        test_episodes: 20,
        gamma: 1.0 - 1.0 / 50.0,
        her,
        ..DdpgHerConfig::default()
    }
}

fn options(epochs: usize) -> TrainOptions {
    TrainOptions::in_memory("point mass", epochs, 2, 1, 1)
}

#[test]
fn her_reaches_ninety_percent_and_plain_ddpg_does_not() {
    let start = std::time::Instant::now();
    let with_her = train(PointMassEnv::default, small_config(true), &options(40)).unwrap();
    let her_time = start.elapsed();
    let without = train(PointMassEnv::default, small_config(false), &options(40)).unwrap();
    println!("with HER ({her_time:.1?}): {}", curve(&with_her.metrics));
    println!("without HER: {}", curve(&without.metrics));
    let last_five = reaches_ninety_percent_and_stays("DDPG + HER", &with_her.metrics);
    assert!(
        best(&without.metrics) < last_five - 0.4,
        "HER is what learns: {}",
        curve(&without.metrics)
    );
}

#[test]
fn td3_with_her_reaches_ninety_percent_on_the_same_budget() {
    let td3 = train(
        PointMassEnv::default,
        small_config(true).with_td3(),
        &options(40),
    )
    .unwrap();
    println!("TD3 + HER: {}", curve(&td3.metrics));
    reaches_ninety_percent_and_stays("TD3 + HER", &td3.metrics);
}

fn best(metrics: &[EpochMetrics]) -> f64 {
    metrics.iter().map(|e| e.test_success).fold(0.0, f64::max)
}

fn curve(metrics: &[EpochMetrics]) -> String {
    metrics
        .iter()
        .map(|e| format!("{:.2}", e.test_success))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Asserts that `metrics` reach 90% test success and average 85% or more over their last five
/// epochs; returns that average.
fn reaches_ninety_percent_and_stays(learner: &str, metrics: &[EpochMetrics]) -> f64 {
    let last_five = metrics
        .iter()
        .rev()
        .take(5)
        .map(|e| e.test_success)
        .sum::<f64>()
        / 5.0;
    assert!(
        best(metrics) >= 0.9,
        "{learner} reaches 90%: {}",
        curve(metrics)
    );
    assert!(
        last_five >= 0.85,
        "{learner} stays there: {}",
        curve(metrics)
    );
    last_five
}
