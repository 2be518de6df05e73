//! Checkpoints, resume and shipped policies: what is saved comes back, a killed run continues,
//! and bad files fail with a message instead of a panic.

use dexcube_env::GoalEnv;
use dexcube_rl::point_mass::PointMassEnv;
use dexcube_rl::{DdpgHerConfig, Policy, TrainOptions, train};

fn config() -> DdpgHerConfig {
    DdpgHerConfig {
        hidden: vec![32, 32],
        cycles_per_epoch: 3,
        batches_per_cycle: 5,
        test_episodes: 4,
        ..DdpgHerConfig::default()
    }
}

fn options(dir: &std::path::Path, epochs: usize, resume: bool) -> TrainOptions {
    TrainOptions {
        epochs,
        envs: 2,
        threads: 1,
        seed: 3,
        out_dir: Some(dir.to_path_buf()),
        resume,
        init_from: None,
        snapshot_every: 2,
        progress: false,
        label: "point mass".into(),
        metadata: serde_json::json!({"env": "point mass"}),
    }
}

fn fresh_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn a_run_writes_its_files_and_resumes_where_it_stopped() {
    let dir = fresh_dir("dexcube-rl-resume");
    let first = train(PointMassEnv::default, config(), &options(&dir, 2, false)).unwrap();
    for file in [
        "checkpoint/actor.safetensors",
        "checkpoint/state.json",
        "best.json",
        "policy.safetensors",
        "metrics.csv",
        "success.png",
        "snapshots/epoch-0001.safetensors",
        "snapshots/epoch-0001.json",
    ] {
        assert!(dir.join(file).is_file(), "{file} written");
    }
    let csv = std::fs::read_to_string(dir.join("metrics.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "a header and two epochs");
    // The curve can be redrawn from the checkpoint alone (a run trained without fonts).
    std::fs::remove_file(dir.join("success.png")).unwrap();
    assert_eq!(
        dexcube_rl::train::replot(&dir).unwrap(),
        dir.join("success.png")
    );
    assert!(dir.join("success.png").is_file(), "success.png redrawn");
    let missing = dexcube_rl::train::replot(&dir.join("no-such-run")).unwrap_err();
    assert!(missing.to_string().contains("state.json"), "{missing}");
    let saved =
        dexcube_rl::checkpoint::load_tensors(&dir.join("checkpoint/actor.safetensors")).unwrap();
    let resumed = train(PointMassEnv::default, config(), &options(&dir, 4, true)).unwrap();
    let now = &resumed.agent.networks()[0];
    let change: f32 = saved
        .iter()
        .zip(now)
        .map(|(a, b)| {
            a.values
                .iter()
                .zip(&b.values)
                .map(|(x, y)| (x - y).abs())
                .sum::<f32>()
        })
        .sum();
    assert!(change > 0.0, "the reloaded actor kept learning");
    assert_eq!(resumed.metrics.len(), 4);
    assert_eq!(
        resumed.metrics[..2],
        first.metrics[..],
        "earlier epochs carried over"
    );
    assert!(resumed.metrics[3].episodes > first.metrics[1].episodes);
    // Resuming with another configuration is refused, with the reason.
    let other = DdpgHerConfig {
        hidden: vec![16],
        ..config()
    };
    let err = train(PointMassEnv::default, other, &options(&dir, 5, true))
        .err()
        .unwrap();
    assert!(err.to_string().contains("cannot resume"), "{err}");
    // So is resuming another environment or mode's run (a changed success test).
    let relabelled = TrainOptions {
        label: "point mass, another goal".into(),
        ..options(&dir, 5, true)
    };
    let err = train(PointMassEnv::default, config(), &relabelled)
        .err()
        .unwrap();
    assert!(err.to_string().contains("is a run of point mass"), "{err}");
}

#[test]
fn a_warm_start_carries_the_networks_into_a_new_run() {
    let source = fresh_dir("dexcube-rl-warm-source");
    train(PointMassEnv::default, config(), &options(&source, 1, false)).unwrap();
    let saved =
        dexcube_rl::checkpoint::load_tensors(&source.join("checkpoint/actor.safetensors")).unwrap();
    let dir = fresh_dir("dexcube-rl-warm");
    let warm = TrainOptions {
        init_from: Some(source.clone()),
        ..options(&dir, 1, false)
    };
    // Another configuration is fine for a new run. With no batches, learning cannot move
    // the actor, so what it holds at the end is what it started from.
    let frozen = DdpgHerConfig {
        batches_per_cycle: 0,
        ..config()
    };
    let run = train(PointMassEnv::default, frozen.clone(), &warm).unwrap();
    assert_eq!(run.metrics.len(), 1, "a new run counts its own epochs");
    let by_name = |mut tensors: Vec<dexcube_rl::params::NamedTensor>| {
        tensors.sort_by(|a, b| a.name.cmp(&b.name));
        tensors
    };
    assert_eq!(
        by_name(run.agent.networks()[0].clone()),
        by_name(saved),
        "the actor came from the source run"
    );
    let card: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("policy.json")).unwrap()).unwrap();
    assert_eq!(
        card["metadata"]["init_from"],
        source.display().to_string(),
        "the card names where it started"
    );
    // Resumed, the run still says where it started.
    let resumed = TrainOptions {
        resume: true,
        ..options(&dir, 2, false)
    };
    train(PointMassEnv::default, frozen, &resumed).unwrap();
    let card: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("policy.json")).unwrap()).unwrap();
    assert_eq!(card["metadata"]["epochs"], 2);
    assert_eq!(card["metadata"]["init_from"], source.display().to_string());
    let other = DdpgHerConfig {
        hidden: vec![16],
        ..config()
    };
    let err = train(PointMassEnv::default, other, &warm).err().unwrap();
    assert!(err.to_string().contains("does not fit"), "{err}");
    let nowhere = TrainOptions {
        init_from: Some(fresh_dir("dexcube-rl-warm-nowhere")),
        ..options(&fresh_dir("dexcube-rl-warm-2"), 1, false)
    };
    let err = train(PointMassEnv::default, config(), &nowhere)
        .err()
        .unwrap();
    assert!(err.to_string().contains("holds no checkpoint"), "{err}");
}

#[test]
fn a_saved_policy_acts_like_the_agent_it_came_from() {
    let dir = fresh_dir("dexcube-rl-policy");
    let trained = train(PointMassEnv::default, config(), &options(&dir, 1, false)).unwrap();
    let policy = Policy::load(&dir.join("policy"), &burn::prelude::Device::flex()).unwrap();
    let mut env = PointMassEnv::default();
    for seed in 0..5 {
        let (obs, _) = env.reset(Some(seed));
        let from_agent = trained
            .agent
            .act(&obs.observation, &obs.desired_goal, 1, None)
            .remove(0);
        let from_policy = policy.act(&obs.observation, &obs.desired_goal);
        for (a, b) in from_agent.iter().zip(&from_policy) {
            assert!((a - b).abs() < 1e-5, "{from_agent:?} vs {from_policy:?}");
        }
    }
    assert_eq!(policy.card.metadata["seed"], 3);
    assert!(policy.card.metadata["episodes"].as_u64().unwrap() > 0);
}

#[test]
fn corrupt_and_mismatched_files_are_clear_errors() {
    let dir = fresh_dir("dexcube-rl-corrupt");
    train(PointMassEnv::default, config(), &options(&dir, 1, false)).unwrap();
    let device = burn::prelude::Device::flex();
    // Truncate the weights.
    let weights = dir.join("policy.safetensors");
    let bytes = std::fs::read(&weights).unwrap();
    std::fs::write(&weights, &bytes[..bytes.len() / 2]).unwrap();
    let err = Policy::load(&dir.join("policy"), &device)
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("policy.safetensors") && err.contains("not a valid checkpoint"),
        "{err}"
    );
    // Weights of another network under this card.
    let small = fresh_dir("dexcube-rl-small");
    let other = DdpgHerConfig {
        hidden: vec![8],
        ..config()
    };
    train(PointMassEnv::default, other, &options(&small, 1, false)).unwrap();
    std::fs::copy(small.join("policy.safetensors"), &weights).unwrap();
    let err = Policy::load(&dir.join("policy"), &device)
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("does not fit this network") && err.contains("shape"),
        "{err}"
    );
    let err = Policy::load(&dir.join("nothing"), &device)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("nothing.json"), "{err}");
}
