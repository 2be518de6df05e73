//! Proof that the learner learns, before spending hours on the hand: DDPG + HER on the point
//! mass, against the same budget without HER.

use dexcube_rl::point_mass::PointMassEnv;
use dexcube_rl::{DdpgHerConfig, TrainOptions, train};

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
    let best =
        |m: &[dexcube_rl::EpochMetrics]| m.iter().map(|e| e.test_success).fold(0.0, f64::max);
    let curve = |m: &[dexcube_rl::EpochMetrics]| {
        m.iter()
            .map(|e| format!("{:.2}", e.test_success))
            .collect::<Vec<_>>()
            .join(" ")
    };
    println!("with HER ({her_time:.1?}): {}", curve(&with_her.metrics));
    println!("without HER: {}", curve(&without.metrics));
    let last_five: f64 = with_her
        .metrics
        .iter()
        .rev()
        .take(5)
        .map(|e| e.test_success)
        .sum::<f64>()
        / 5.0;
    assert!(
        best(&with_her.metrics) >= 0.9,
        "DDPG + HER reaches 90%: {}",
        curve(&with_her.metrics)
    );
    assert!(
        last_five >= 0.85,
        "and stays there: {}",
        curve(&with_her.metrics)
    );
    assert!(
        best(&without.metrics) < last_five - 0.4,
        "HER is what learns: {}",
        curve(&without.metrics)
    );
}
