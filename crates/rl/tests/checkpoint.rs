//! Checkpoints, resume and shipped policies: what is saved comes back, a killed run continues,
//! and bad files fail with a message instead of a panic.

use std::sync::Arc;

use dexcube_env::{Goal, GoalEnv, GoalLead, Info, Observation, Spaces, Transition};
use dexcube_rl::handover::{FarHandover, Handover};
use dexcube_rl::params::NamedTensor;
use dexcube_rl::point_mass::{PointGoal, PointMassEnv};
use dexcube_rl::{Agent, DdpgHerConfig, Policy, TrainOptions, train};

mod common;
use common::{config, fresh_dir};

fn options(dir: &std::path::Path, epochs: usize, resume: bool) -> TrainOptions {
    TrainOptions {
        out_dir: Some(dir.to_path_buf()),
        resume,
        snapshot_every: 2,
        metadata: serde_json::json!({"env": "point mass"}),
        ..TrainOptions::in_memory("point mass", epochs, 2, 1, 3)
    }
}

/// Parameters in name order, to compare networks whatever order they were read in.
fn by_name(mut tensors: Vec<NamedTensor>) -> Vec<NamedTensor> {
    tensors.sort_by(|a, b| a.name.cmp(&b.name));
    tensors
}

/// The agent's and the policy's actions on the first state of point-mass episodes seeded
/// 0, 1, … `episodes` - 1.
fn first_actions(agent: &Agent, policy: &Policy, episodes: u64) -> Vec<(Vec<f64>, Vec<f64>)> {
    let mut env = PointMassEnv::default();
    (0..episodes)
        .map(|seed| {
            let (obs, _) = env.reset(Some(seed));
            let from_agent = agent
                .act(&obs.observation, &obs.desired_goal, 1, None)
                .remove(0);
            (from_agent, policy.act(&obs.observation, &obs.desired_goal))
        })
        .collect()
}

/// The message of loading the policy at `prefix`, which must fail.
fn load_error(prefix: &std::path::Path) -> String {
    match Policy::load(prefix, &burn::prelude::Device::flex()) {
        Ok(_) => panic!("{} loaded", prefix.display()),
        Err(e) => e.to_string(),
    }
}

/// A one-epoch point-mass run of a smaller network (one hidden layer of 8), in a fresh folder.
fn small_network_run(name: &str) -> std::path::PathBuf {
    let dir = fresh_dir(name);
    let small = DdpgHerConfig {
        hidden: vec![8],
        ..config()
    };
    train(PointMassEnv::default, small, &options(&dir, 1, false)).unwrap();
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
    let change = dexcube_rl::params::l1_distance(&saved, now);
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

/// An epoch's record without its clock times, which no two runs share.
fn untimed(m: &dexcube_rl::EpochMetrics) -> dexcube_rl::EpochMetrics {
    dexcube_rl::EpochMetrics {
        env_steps_per_s: 0.0,
        rollout_s: 0.0,
        learning_s: 0.0,
        other_s: 0.0,
        wall_s: 0.0,
        ..m.clone()
    }
}

#[test]
fn a_resumed_run_goes_on_exactly_as_an_uninterrupted_one() {
    // TD3, for its second critic, its delayed actor and its noise stream, and a buffer of two
    // epochs' transitions, so that older epochs' episodes leave it and their files go.
    let td3 = DdpgHerConfig {
        buffer_size: 600,
        ..config().with_td3()
    };
    let whole_dir = fresh_dir("dexcube-rl-exact-whole");
    let whole = train(
        PointMassEnv::default,
        td3.clone(),
        &options(&whole_dir, 5, false),
    )
    .unwrap();
    let split_dir = fresh_dir("dexcube-rl-exact-split");
    train(
        PointMassEnv::default,
        td3.clone(),
        &options(&split_dir, 2, false),
    )
    .unwrap();
    // A kill while the next checkpoint was being written leaves part of it aside, and the
    // interrupted epoch's episodes: neither may count.
    let aside = split_dir.join("checkpoint.tmp");
    std::fs::create_dir_all(&aside).unwrap();
    std::fs::write(aside.join("actor.safetensors"), b"half").unwrap();
    std::fs::write(split_dir.join("replay/epoch-0002.bin"), b"half").unwrap();
    let split = train(
        PointMassEnv::default,
        td3.clone(),
        &options(&split_dir, 5, true),
    )
    .unwrap();
    let (a, b): (Vec<_>, Vec<_>) = (
        whole.metrics.iter().map(untimed).collect(),
        split.metrics.iter().map(untimed).collect(),
    );
    assert_eq!(a, b, "every epoch's figures alike");
    for (x, y) in whole
        .agent
        .networks()
        .into_iter()
        .zip(split.agent.networks())
    {
        assert_eq!(by_name(x), by_name(y), "the same weights, bit for bit");
    }
    assert_eq!(
        whole.agent.twin_networks().map(|t| t.map(by_name)),
        split.agent.twin_networks().map(|t| t.map(by_name))
    );
    // Only the epochs whose episodes the buffer still holds keep their files.
    let files = |dir: &std::path::Path| {
        let mut names: Vec<String> = std::fs::read_dir(dir.join("replay"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    assert_eq!(files(&whole_dir), ["epoch-0003.bin", "epoch-0004.bin"]);
    assert_eq!(files(&split_dir), files(&whole_dir));
    assert!(!aside.exists(), "the part written aside is gone");
    // Without its episodes the buffer cannot be refilled, and the resume says which file.
    std::fs::remove_file(split_dir.join("replay/epoch-0004.bin")).unwrap();
    let err = train(
        PointMassEnv::default,
        td3.clone(),
        &options(&split_dir, 6, true),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(err.contains("epoch-0004.bin"), "{err}");
    std::fs::write(split_dir.join("replay/epoch-0004.bin"), b"DXEPIS01").unwrap();
    let err = train(PointMassEnv::default, td3, &options(&split_dir, 6, true))
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("epoch-0004.bin") && err.contains("cut short"),
        "{err}"
    );
}

/// A run killed while its new checkpoint was swapped in (the old one moved aside, the new one
/// complete) resumes from the new one.
#[test]
fn a_checkpoint_caught_between_swaps_is_found_again() {
    let dir = fresh_dir("dexcube-rl-swap");
    train(PointMassEnv::default, config(), &options(&dir, 2, false)).unwrap();
    std::fs::rename(dir.join("checkpoint"), dir.join("checkpoint.tmp")).unwrap();
    let resumed = train(PointMassEnv::default, config(), &options(&dir, 3, true)).unwrap();
    assert_eq!(resumed.metrics.len(), 3, "it went on from epoch 2");
    assert!(dir.join("checkpoint/state.json").is_file());
}

#[test]
fn a_resumed_run_keeps_how_it_began() {
    // The first call names the warm start and the critic-only epochs; a resume names neither.
    let dir = fresh_dir("dexcube-rl-resume-start");
    let began = TrainOptions {
        critic_only_epochs: 3,
        metadata: serde_json::json!({"env": "point mass", "init_actor": "models/somewhere"}),
        ..options(&dir, 1, false)
    };
    train(PointMassEnv::default, config(), &began).unwrap();
    let held =
        dexcube_rl::checkpoint::load_tensors(&dir.join("checkpoint/actor.safetensors")).unwrap();
    let resumed = train(PointMassEnv::default, config(), &options(&dir, 3, true)).unwrap();
    let [actor, ..] = resumed.agent.networks();
    let change = dexcube_rl::params::l1_distance(&held, &actor);
    assert_eq!(
        change, 0.0,
        "epochs 2 and 3 are still the run's critic-only epochs"
    );
    let card: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("policy.json")).unwrap()).unwrap();
    assert_eq!(
        card["metadata"]["environment"]["init_actor"], "models/somewhere",
        "the resumed run's card names the warm start"
    );
}

/// Trains a one-epoch source run in `NAME-source`, and returns it with the folder of a new run
/// (`NAME`), the options that warm-start that run from the source, and a configuration
/// without batches. Another configuration is fine for a new run; with no batches, learning
/// cannot move the actor or critic, so what they hold at the end is what they started from.
fn warm_start_from_a_new_run(
    name: &str,
) -> (
    std::path::PathBuf,
    std::path::PathBuf,
    TrainOptions,
    DdpgHerConfig,
) {
    let source = fresh_dir(&format!("{name}-source"));
    train(PointMassEnv::default, config(), &options(&source, 1, false)).unwrap();
    let dir = fresh_dir(name);
    let warm = TrainOptions {
        init_from: Some(source.clone()),
        ..options(&dir, 1, false)
    };
    let frozen = DdpgHerConfig {
        batches_per_cycle: 0,
        ..config()
    };
    (source, dir, warm, frozen)
}

#[test]
fn a_warm_start_carries_the_networks_into_a_new_run() {
    let (source, dir, warm, frozen) = warm_start_from_a_new_run("dexcube-rl-warm");
    let saved =
        dexcube_rl::checkpoint::load_tensors(&source.join("checkpoint/actor.safetensors")).unwrap();
    let run = train(PointMassEnv::default, frozen.clone(), &warm).unwrap();
    assert_eq!(run.metrics.len(), 1, "a new run counts its own epochs");
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

/// A warm start can take its actor from a policy of the run, an earlier snapshot than the
/// run's last checkpoint (as a shipped policy may be), and hold it while only the critic
/// learns.
#[test]
fn a_warm_start_takes_the_actor_of_a_named_policy_and_can_hold_it() {
    let source = fresh_dir("dexcube-rl-warm-actor-source");
    train(PointMassEnv::default, config(), &options(&source, 3, false)).unwrap();
    let tensors =
        |path: std::path::PathBuf| by_name(dexcube_rl::checkpoint::load_tensors(&path).unwrap());
    let snapshot = source.join("snapshots/epoch-0001");
    let (earlier, last) = (
        tensors(snapshot.with_extension("safetensors")),
        tensors(source.join("checkpoint/actor.safetensors")),
    );
    assert!(dexcube_rl::params::l1_distance(&earlier, &last) > 0.0);
    let dir = fresh_dir("dexcube-rl-warm-actor");
    let held = TrainOptions {
        init_from: Some(source.clone()),
        init_actor: Some(snapshot),
        critic_only_epochs: 1,
        ..options(&dir, 1, false)
    };
    let run = train(PointMassEnv::default, config(), &held).unwrap();
    let [actor, critic, ..] = run.agent.networks().map(by_name);
    assert_eq!(
        actor, earlier,
        "the named policy's actor, held through the epoch"
    );
    let source_critic = tensors(source.join("checkpoint/critic.safetensors"));
    assert!(
        dexcube_rl::params::l1_distance(&critic, &source_critic) > 0.0,
        "while the critic learnt"
    );
}

/// A policy alone can warm-start a run: its actor and normalisers carry over, the critic starts
/// afresh. With an anchor the actor learns while held near that start, and a resumed run keeps
/// the same anchor.
#[test]
fn a_policy_alone_warm_starts_the_actor_and_an_anchor_holds_it_near() {
    let source = fresh_dir("dexcube-rl-anchor-source");
    train(PointMassEnv::default, config(), &options(&source, 1, false)).unwrap();
    let start =
        by_name(dexcube_rl::checkpoint::load_tensors(&source.join("policy.safetensors")).unwrap());
    let from_policy = |name: &str, anchor: f64| {
        let dir = fresh_dir(name);
        let options = TrainOptions {
            init_actor: Some(source.join("policy")),
            ..options(&dir, 3, false)
        };
        let config = DdpgHerConfig {
            anchor,
            actor_lr: 1e-2,
            ..config()
        };
        (dir, options, config)
    };
    let (_, held, frozen) = from_policy("dexcube-rl-anchor-frozen", 0.0);
    let frozen = DdpgHerConfig {
        batches_per_cycle: 0,
        ..frozen
    };
    let run = train(PointMassEnv::default, frozen, &held).unwrap();
    assert_eq!(
        by_name(run.agent.networks()[0].clone()),
        start,
        "the actor is the policy's"
    );
    // How far the trained actor's actions are from the start's, on 20 episodes' first states.
    let device = burn::prelude::Device::flex();
    let started = Policy::load(&source.join("policy"), &device).unwrap();
    let moved = |anchor: f64| {
        let (dir, options, config) = from_policy(&format!("dexcube-rl-anchor-{anchor}"), anchor);
        let config = DdpgHerConfig {
            batches_per_cycle: 20,
            ..config
        };
        let run = train(PointMassEnv::default, config, &options).unwrap();
        let distance: f64 = first_actions(&run.agent, &started, 20)
            .iter()
            .flat_map(|(now, then)| now.iter().zip(then).map(|(a, b)| (a - b).abs()))
            .sum();
        (dir, distance)
    };
    let (_, free) = moved(0.0);
    let (dir, anchored) = moved(100.0);
    assert!(anchored > 0.0, "the anchored actor still learns");
    assert!(
        anchored < 0.5 * free,
        "the anchor holds the actor near its start: {anchored} against {free}"
    );
    let (_, mut resumed, config) = from_policy("dexcube-rl-anchor-unused", 100.0);
    let config = DdpgHerConfig {
        batches_per_cycle: 20,
        ..config
    };
    resumed.resume = true;
    resumed.out_dir = Some(dir.clone());
    resumed.init_actor = None;
    resumed.epochs = 4;
    let run = train(PointMassEnv::default, config, &resumed).unwrap();
    assert_eq!(run.metrics.len(), 4);
    let anchor = run.agent.anchor().unwrap();
    assert_eq!(
        by_name(anchor.actor.clone()),
        start,
        "the resumed run holds the same anchor"
    );
    assert_eq!(
        [&anchor.observation_norm, &anchor.goal_norm],
        [&started.card.observation_norm, &started.card.goal_norm],
        "with the normalisers it started from, while the run's own moved on"
    );
    assert_ne!(run.agent.observation_norm, anchor.observation_norm);
    let nowhere = TrainOptions {
        init_actor: None,
        ..from_policy("dexcube-rl-anchor-nowhere", 1.0).1
    };
    let err = train(
        PointMassEnv::default,
        from_policy("dexcube-rl-anchor-unused", 1.0).2,
        &nowhere,
    )
    .err()
    .unwrap();
    assert!(err.to_string().contains("needs a warm start"), "{err}");
}

/// The point mass with its distance from the origin appended, as a third goal component (0
/// desired) that its success test also reads, as LayerOpEnv's good state joins the layer
/// angle; or as a third observation, as LayerOpEnv may show the cube's misalignment.
struct PointMassWithRadius {
    env: PointMassEnv,
    radius_in: RadiusIn,
}

#[derive(Clone, Copy, PartialEq)]
enum RadiusIn {
    Goal,
    Observation,
}

struct InsideRadius;

impl Goal for InsideRadius {
    fn size(&self) -> usize {
        3
    }
    fn errors(&self, achieved: &[f64], desired: &[f64]) -> (f64, f64) {
        PointGoal.errors(achieved, desired)
    }
    fn is_success(&self, achieved: &[f64], desired: &[f64]) -> bool {
        PointGoal.is_success(achieved, desired) && achieved[2] < 0.5
    }
}

impl PointMassWithRadius {
    fn widen(&self, mut observation: Observation) -> Observation {
        let radius = observation.achieved_goal[0].hypot(observation.achieved_goal[1]);
        match self.radius_in {
            RadiusIn::Goal => {
                observation.achieved_goal.push(radius);
                observation.desired_goal.push(0.0);
            }
            RadiusIn::Observation => observation.observation.push(radius),
        }
        observation
    }
}

impl GoalEnv for PointMassWithRadius {
    fn spaces(&self) -> Spaces {
        let spaces = self.env.spaces();
        match self.radius_in {
            RadiusIn::Goal => Spaces { goal: 3, ..spaces },
            RadiusIn::Observation => Spaces {
                observation: 3,
                ..spaces
            },
        }
    }
    fn goal(&self) -> Arc<dyn Goal> {
        match self.radius_in {
            RadiusIn::Goal => Arc::new(InsideRadius),
            RadiusIn::Observation => Arc::new(PointGoal),
        }
    }
    fn reset(&mut self, seed: Option<u64>) -> (Observation, Info) {
        let (observation, info) = self.env.reset(seed);
        (self.widen(observation), info)
    }
    fn step(&mut self, action: &[f64]) -> Transition {
        let t = self.env.step(action);
        Transition {
            observation: self.widen(t.observation),
            ..t
        }
    }
}

/// Warm-starts a run on the point mass with its radius in `radius_in` from a run without it,
/// and checks that each network's first layer gained one input at `at` with zero weights, so
/// the networks compute what they did. Returns the new run.
fn warm_start_onto_a_wider_input(
    name: &str,
    radius_in: RadiusIn,
    at: usize,
) -> dexcube_rl::train::Trained {
    let (source, _, warm, frozen) = warm_start_from_a_new_run(name);
    let make = || PointMassWithRadius {
        env: PointMassEnv::default(),
        radius_in,
    };
    let run = train(make, frozen, &warm).unwrap();
    for (k, name) in ["actor", "critic", "target_actor", "target_critic"]
        .into_iter()
        .enumerate()
    {
        let saved = dexcube_rl::checkpoint::load_tensors(
            &source.join(format!("checkpoint/{name}.safetensors")),
        )
        .unwrap();
        let now = &run.agent.networks()[k];
        // The targets move toward the networks by polyak averaging even without batches:
        // only the actor and critic must hold exactly what was saved.
        let exact = k < 2;
        for tensor in &saved {
            let widened = now.iter().find(|t| t.name == tensor.name).unwrap();
            if tensor.name != "layers.0.weight" {
                if !exact {
                    continue;
                }
                assert_eq!(widened, tensor, "{name} {} unchanged", tensor.name);
                continue;
            }
            let outputs = tensor.shape[1];
            assert_eq!(
                widened.shape,
                [tensor.shape[0] + 1, outputs],
                "{name}: one more input"
            );
            let row = |t: &dexcube_rl::params::NamedTensor, r: usize| {
                t.values[r * outputs..(r + 1) * outputs].to_vec()
            };
            assert!(
                row(widened, at).iter().all(|&w| w == 0.0),
                "{name}: the new input weighs 0"
            );
            if exact {
                for r in 0..tensor.shape[0] {
                    let shifted = if r < at { r } else { r + 1 };
                    assert_eq!(
                        row(widened, shifted),
                        row(tensor, r),
                        "{name}: input {r} kept"
                    );
                }
            }
        }
    }
    run
}

/// A success test that gains a goal component warm-starts from the old run: the new input
/// comes in after the observation and the old goal, and the goal normaliser gains the
/// component.
#[test]
fn a_warm_start_onto_a_longer_goal_gives_the_new_input_zero_weights() {
    let run = warm_start_onto_a_wider_input("dexcube-rl-widen", RadiusIn::Goal, 2 + 2);
    assert_eq!(run.agent.goal_norm.size(), 3);
    assert_eq!(run.agent.observation_norm.size(), 2);
    assert!(
        run.agent.goal_norm.mean(2) > 0.0,
        "the new component learnt from fresh rows"
    );
}

/// An observation that gains a number warm-starts from the old run: the new input comes in
/// after the old observation, before the goal, and the observation normaliser gains it.
#[test]
fn a_warm_start_onto_a_longer_observation_gives_the_new_input_zero_weights() {
    let run =
        warm_start_onto_a_wider_input("dexcube-rl-widen-observation", RadiusIn::Observation, 2);
    assert_eq!(run.agent.observation_norm.size(), 3);
    assert_eq!(run.agent.goal_norm.size(), 2);
    assert!(
        run.agent.observation_norm.mean(2) > 0.0,
        "the new observation learnt from fresh rows"
    );
}

#[test]
fn a_saved_policy_acts_like_the_agent_it_came_from() {
    let dir = fresh_dir("dexcube-rl-policy");
    let trained = train(PointMassEnv::default, config(), &options(&dir, 1, false)).unwrap();
    let policy = Policy::load(&dir.join("policy"), &burn::prelude::Device::flex()).unwrap();
    for (from_agent, from_policy) in first_actions(&trained.agent, &policy, 5) {
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
    // Truncate the weights.
    let weights = dir.join("policy.safetensors");
    let bytes = std::fs::read(&weights).unwrap();
    std::fs::write(&weights, &bytes[..bytes.len() / 2]).unwrap();
    let err = load_error(&dir.join("policy"));
    assert!(
        err.contains("policy.safetensors") && err.contains("not a valid checkpoint"),
        "{err}"
    );
    // Weights of another network under this card.
    let small = small_network_run("dexcube-rl-small");
    std::fs::copy(small.join("policy.safetensors"), &weights).unwrap();
    let err = load_error(&dir.join("policy"));
    assert!(
        err.contains("does not fit this network") && err.contains("shape"),
        "{err}"
    );
    let err = load_error(&dir.join("nothing"));
    assert!(err.contains("nothing.json"), "{err}");
}

#[test]
fn a_weight_average_of_snapshots_holds_their_mean_weights_and_pooled_normalisers() {
    let dir = fresh_dir("dexcube-rl-average");
    train(PointMassEnv::default, config(), &options(&dir, 4, false)).unwrap();
    let members = [
        dir.join("snapshots/epoch-0001"),
        dir.join("snapshots/epoch-0003"),
    ];
    let out = dir.join("average");
    Policy::average(&members, &out, "dexcube average ...").unwrap();
    let weights = |prefix: &std::path::Path| {
        by_name(
            dexcube_rl::checkpoint::load_tensors(&prefix.with_extension("safetensors")).unwrap(),
        )
    };
    let (early, late, mean) = (weights(&members[0]), weights(&members[1]), weights(&out));
    assert_ne!(
        early, late,
        "the snapshots differ, so the mean is not one of them"
    );
    assert_eq!(mean.len(), early.len());
    for ((e, l), m) in early.iter().zip(&late).zip(&mean) {
        assert_eq!((&m.name, &m.shape), (&e.name, &e.shape));
        for ((e, l), m) in e.values.iter().zip(&l.values).zip(&m.values) {
            assert!((m - (e + l) / 2.0).abs() < 1e-6, "{}: {m} vs {e}, {l}", e);
        }
    }
    let device = burn::prelude::Device::flex();
    let [first, second] = members
        .each_ref()
        .map(|p| Policy::load(p, &device).unwrap());
    let average = Policy::load(&out, &device).unwrap();
    let pooled = dexcube_rl::normalizer::Normalizer::pooled(&[
        &first.card.observation_norm,
        &second.card.observation_norm,
    ]);
    assert_eq!(Some(average.card.observation_norm.clone()), pooled);
    let metadata = &average.card.metadata;
    assert_eq!(metadata["environment"], first.card.metadata["environment"]);
    assert_eq!(metadata["averaged"][1], members[1].display().to_string());
    assert_eq!(metadata["command"], "dexcube average ...");

    // A policy of another network is refused, by name.
    let small = small_network_run("dexcube-rl-average-small");
    let err = Policy::average(&[members[0].clone(), small.join("policy")], &out, "")
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("other network sizes") && err.contains("policy.safetensors"),
        "{err}"
    );
}

/// An ensemble acts with the mean of its members' actions, each member reading the leading part
/// of the observation through its own normalisers; it is refused where it cannot act as one,
/// and cannot be averaged, joined again or trained from.
#[test]
fn an_ensemble_acts_with_the_mean_of_its_members_actions() {
    let dir = fresh_dir("dexcube-rl-ensemble");
    train(PointMassEnv::default, config(), &options(&dir, 4, false)).unwrap();
    let wider = fresh_dir("dexcube-rl-ensemble-wider");
    let make = || PointMassWithRadius {
        env: PointMassEnv::default(),
        radius_in: RadiusIn::Observation,
    };
    train(make, config(), &options(&wider, 1, false)).unwrap();
    let members = [
        wider.join("policy"),
        dir.join("snapshots/epoch-0001"),
        dir.join("snapshots/epoch-0003"),
    ];
    let out = dir.join("ensemble");
    Policy::ensemble(&members, &out, "dexcube ensemble ...").unwrap();
    let device = burn::prelude::Device::flex();
    let loaded = members
        .each_ref()
        .map(|p| Policy::load(p, &device).unwrap());
    let ensemble = Policy::load(&out, &device).unwrap();
    assert_eq!(ensemble.members(), 3);
    assert_eq!(
        ensemble.card.dims, loaded[0].card.dims,
        "the first member's sizes"
    );
    let metadata = &ensemble.card.metadata;
    assert_eq!(
        metadata["environment"],
        loaded[0].card.metadata["environment"]
    );
    assert_eq!(metadata["ensemble"][2], members[2].display().to_string());
    assert_eq!(metadata["command"], "dexcube ensemble ...");
    assert!(
        metadata["label"]
            .as_str()
            .unwrap()
            .starts_with("ensemble of 3, first ")
    );
    let mut env = make();
    for seed in 0..5 {
        let (obs, _) = env.reset(Some(seed));
        assert_eq!(obs.observation.len(), 3);
        let actions: Vec<Vec<f64>> = loaded
            .iter()
            .map(|p| p.act(&obs.observation, &obs.desired_goal))
            .collect();
        assert_eq!(
            actions[1],
            loaded[1].act(&obs.observation[..2], &obs.desired_goal),
            "a narrower member reads the leading part"
        );
        assert_ne!(actions[1], actions[2], "the members differ");
        let together = ensemble.act(&obs.observation, &obs.desired_goal);
        for (k, a) in together.iter().enumerate() {
            let mean = actions.iter().map(|x| x[k]).sum::<f64>() / 3.0;
            assert!(
                (a - mean).abs() < 1e-6,
                "action {k}: {a} against the mean {mean}"
            );
        }
    }

    let refused = |result: Result<(), dexcube_rl::checkpoint::CheckpointError>| {
        result.expect_err("refused").to_string()
    };
    let narrower_first = [members[1].clone(), members[0].clone()];
    let err = refused(Policy::ensemble(
        &narrower_first,
        &out.with_file_name("x"),
        "",
    ));
    assert!(err.contains("first observes the most"), "{err}");
    let err = refused(Policy::ensemble(
        &[out.clone(), members[1].clone()],
        &dir.join("x"),
        "",
    ));
    assert!(err.contains("an ensemble already"), "{err}");
    let err = refused(Policy::average(
        &[members[1].clone(), out.clone()],
        &dir.join("x"),
        "",
    ));
    assert!(err.contains("cannot be averaged"), "{err}");
    let from_ensemble = TrainOptions {
        init_from: Some(dir.clone()),
        init_actor: Some(out.clone()),
        ..options(&fresh_dir("dexcube-rl-ensemble-warm"), 1, false)
    };
    let err = train(PointMassEnv::default, config(), &from_ensemble)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("ensemble of 3 policies"), "{err}");
}

#[test]
fn a_td3_run_keeps_its_second_critic_and_a_warm_start_from_ddpg_makes_a_new_one() {
    let dir = fresh_dir("dexcube-rl-td3");
    let td3 = config().with_td3();
    let first = train(PointMassEnv::default, td3.clone(), &options(&dir, 2, false)).unwrap();
    let load = |name: &str| {
        by_name(
            dexcube_rl::checkpoint::load_tensors(
                &dir.join(format!("checkpoint/{name}.safetensors")),
            )
            .unwrap(),
        )
    };
    let [second, target] = first
        .agent
        .twin_networks()
        .expect("TD3 has a second critic");
    assert_eq!(by_name(second.clone()), load("critic2"));
    assert_eq!(by_name(target), load("target_critic2"));
    // A resume with nothing left to train holds what the checkpoint saved.
    let resumed = train(PointMassEnv::default, td3.clone(), &options(&dir, 2, true)).unwrap();
    assert_eq!(
        by_name(resumed.agent.twin_networks().unwrap()[0].clone()),
        load("critic2")
    );
    // Resuming it as DDPG is refused: the configuration differs.
    let err = train(PointMassEnv::default, config(), &options(&dir, 3, true))
        .err()
        .unwrap();
    assert!(err.to_string().contains("cannot resume"), "{err}");

    // From a DDPG run the first critic carries over and the second starts as made, not as a
    // copy that would learn the same as the first.
    let (source, _, warm, frozen) = warm_start_from_a_new_run("dexcube-rl-td3-warm");
    let run = train(PointMassEnv::default, frozen.with_td3(), &warm).unwrap();
    let critic = by_name(
        dexcube_rl::checkpoint::load_tensors(&source.join("checkpoint/critic.safetensors"))
            .unwrap(),
    );
    assert_eq!(by_name(run.agent.networks()[1].clone()), critic);
    let second = by_name(run.agent.twin_networks().unwrap()[0].clone());
    assert!(dexcube_rl::params::l1_distance(&second, &critic) > 0.0);
}

/// A student fitted by DAgger's labels learns to act as the ensemble that taught it, keeps the
/// first member's card, and is written and read back as a single policy.
#[test]
fn a_distilled_student_acts_as_its_ensemble_does() {
    use dexcube_rl::distil::{Demonstrations, DistilConfig, fit};
    let dir = fresh_dir("dexcube-rl-distil");
    train(PointMassEnv::default, config(), &options(&dir, 4, false)).unwrap();
    let members = [
        dir.join("snapshots/epoch-0001"),
        dir.join("snapshots/epoch-0003"),
    ];
    let teacher_path = dir.join("ensemble");
    Policy::ensemble(&members, &teacher_path, "").unwrap();
    let device = burn::prelude::Device::flex();
    let teacher = Policy::load(&teacher_path, &device).unwrap();
    let student = teacher.first_member(serde_json::json!({"label": "student"}));
    assert_eq!(student.members(), 1);
    let first = Policy::load(&members[0], &device).unwrap();

    // The student's own episodes, labelled by the teacher (DAgger's later rounds).
    let mut env = PointMassEnv::default();
    let mut demonstrations = Demonstrations::default();
    for seed in 0..20 {
        let (mut obs, _) = env.reset(Some(seed));
        loop {
            let taught =
                demonstrations.label(&teacher, &student, &obs.observation, &obs.desired_goal);
            assert_eq!(taught, teacher.act(&obs.observation, &obs.desired_goal));
            let own = student.act(&obs.observation, &obs.desired_goal);
            assert_eq!(own, first.act(&obs.observation, &obs.desired_goal));
            let t = env.step(&own);
            if t.terminated || t.truncated {
                break;
            }
            obs = t.observation;
        }
    }
    assert!(demonstrations.rows() >= 20);
    let before = demonstrations.mean_squared_error(&student);
    assert!(
        before > 0.0,
        "the members differ, so the first alone is not the ensemble"
    );
    let config = DistilConfig {
        epochs: 100,
        ..DistilConfig::default()
    };
    let fitted = fit(&student, &demonstrations, config, 0).unwrap();
    let after = demonstrations.mean_squared_error(&fitted);
    assert!(
        after < before / 4.0,
        "the fit closes most of the gap: {before} -> {after}"
    );
    assert_eq!(fitted.card.observation_norm, student.card.observation_norm);

    let out = dir.join("student");
    fitted.write(&out).unwrap();
    let read_back = Policy::load(&out, &device).unwrap();
    assert_eq!(read_back.card.metadata["label"], "student");
    let (obs, _) = env.reset(Some(99));
    assert_eq!(
        read_back.act(&obs.observation, &obs.desired_goal),
        fitted.act(&obs.observation, &obs.desired_goal)
    );
    let err = teacher.write(&dir.join("x")).err().unwrap().to_string();
    assert!(err.contains("written by `Policy::ensemble`"), "{err}");
}

#[test]
fn a_policy_guided_by_its_run_s_critics_ships_them_and_bad_critics_are_clear_errors() {
    let dir = fresh_dir("dexcube-rl-guide");
    train(PointMassEnv::default, config(), &options(&dir, 1, false)).unwrap();
    let device = burn::prelude::Device::flex();
    let policy = dir.join("policy");
    let guided = |candidates: usize, name: &str| {
        let out = dir.join(name);
        Policy::guide(&policy, &dir, (candidates, 0.2, 0), &out, "test").unwrap();
        Policy::load(&out, &device).unwrap()
    };
    let plain = Policy::load(&policy, &device).unwrap();
    let (unmoved, moved) = (guided(0, "unmoved"), guided(32, "moved"));
    assert_eq!(
        moved.card.guide.as_ref().unwrap().critics,
        1,
        "DDPG: one critic"
    );
    let mut env = PointMassEnv::default();
    let mut differs = false;
    for seed in 0..5 {
        let (obs, _) = env.reset(Some(seed));
        let act = |p: &Policy| p.act(&obs.observation, &obs.desired_goal);
        assert_eq!(
            act(&plain),
            act(&unmoved),
            "no candidates: the actor's own action"
        );
        let chosen = act(&moved);
        assert!(chosen.iter().all(|a| a.abs() <= 1.0), "{chosen:?}");
        differs |= chosen != act(&plain);
    }
    assert!(
        differs,
        "with candidates the critic chose another action somewhere"
    );
    let err = |result: Result<(), dexcube_rl::checkpoint::CheckpointError>| {
        result.err().unwrap().to_string()
    };
    // A guided policy is not guided again, nor trained from.
    let again = Policy::guide(
        &dir.join("moved"),
        &dir,
        (4, 0.2, 0),
        &dir.join("x"),
        "test",
    );
    assert!(err(again).contains("guided already"));
    let joined = Policy::ensemble(&[dir.join("moved"), policy.clone()], &dir.join("x"), "test");
    assert!(err(joined).contains("guided by the critics of"));
    let no_run = Policy::guide(&policy, &dir.join("x"), (4, 0.2, 0), &dir.join("y"), "test");
    assert!(err(no_run).contains("not a training run's folder"));
    // The critics of a run of another width under this run's state.
    let small = small_network_run("dexcube-rl-guide-small");
    let critic = dir.join("checkpoint").join("critic.safetensors");
    std::fs::copy(small.join("checkpoint").join("critic.safetensors"), &critic).unwrap();
    Policy::guide(&policy, &dir, (4, 0.2, 0), &dir.join("bad"), "test").unwrap();
    let message = load_error(&dir.join("bad"));
    assert!(
        message.contains("bad.safetensors") && message.contains("guide's critic 0"),
        "{message}"
    );
}

#[test]
fn a_policy_led_on_acts_toward_the_goal_led_on_and_is_not_combined() {
    let dir = fresh_dir("dexcube-rl-goal-lead");
    train(PointMassEnv::default, config(), &options(&dir, 1, false)).unwrap();
    let device = burn::prelude::Device::flex();
    let policy = dir.join("policy");
    let lead = GoalLead {
        share: 0.5,
        within: 0.5,
    };
    // A dot in the name is part of it, not an extension to replace.
    let out = dir.join("led0.5");
    Policy::led(&policy, lead, &out, "dexcube goal-lead ...").unwrap();
    assert!(dir.join("led0.5.safetensors").is_file() && dir.join("led0.5.json").is_file());
    let (plain, led) = (
        Policy::load(&policy, &device).unwrap(),
        Policy::load(&out, &device).unwrap(),
    );
    assert_eq!(led.card.goal_lead, Some(lead));
    assert_eq!(led.card.metadata["led"], policy.display().to_string());
    // The point mass's goal read as a layer angle and a misalignment: only the first moves on.
    let test = dexcube_env::LayerGoal::square();
    let mut env = PointMassEnv::default();
    let mut differs = false;
    for seed in 0..5 {
        let (obs, _) = env.reset(Some(seed));
        let (achieved, desired) = (&obs.achieved_goal, &obs.desired_goal);
        let shown = test.led(achieved, desired, lead);
        assert_eq!(
            led.episode()
                .act_toward(&obs.observation, desired, || achieved.clone(), &test),
            plain.act(&obs.observation, &shown)
        );
        let unread = || -> Vec<f64> { panic!("a policy without a lead reads no achieved goal") };
        assert_eq!(
            plain
                .episode()
                .act_toward(&obs.observation, desired, unread, &test),
            plain.act(&obs.observation, desired),
            "a policy without a lead is shown its goal as it is"
        );
        differs |= shown != obs.desired_goal;
    }
    assert!(differs, "some goal lay within reach of the lead");
    let err = |result: Result<(), dexcube_rl::checkpoint::CheckpointError>| {
        result.err().unwrap().to_string()
    };
    let again = Policy::led(&out, lead, &dir.join("x"), "test");
    assert!(err(again).contains("led on already"));
    let joined = Policy::ensemble(&[out.clone(), policy.clone()], &dir.join("x"), "test");
    assert!(err(joined).contains("shown its goal led on (by 0.5 within 0.5 rad)"));
    // Either file's name names the same policy.
    for named in ["led0.5.json", "led0.5.safetensors"] {
        let again = Policy::load(&dir.join(named), &device).unwrap();
        assert_eq!(again.card.goal_lead, Some(lead), "{named}");
    }
}

/// An ensemble that hands over acts as the ensemble until its episode has stalled for its
/// patience, then as its member to the end; a fresh episode begins as the ensemble again. One
/// that names a member to act first acts as that member alone until then; one that lets go
/// takes the neutral action for as many steps before the member acts, and so may a single
/// policy. A single policy not letting go, a member it lacks, a member handing to itself and a
/// second handover are refused.
#[test]
fn an_ensemble_hands_a_stalled_episode_to_its_member() {
    let dir = fresh_dir("dexcube-rl-handover");
    train(PointMassEnv::default, config(), &options(&dir, 4, false)).unwrap();
    let device = burn::prelude::Device::flex();
    let members = [
        dir.join("snapshots/epoch-0001"),
        dir.join("snapshots/epoch-0003"),
    ];
    let ensemble = dir.join("ensemble");
    Policy::ensemble(&members, &ensemble, "dexcube ensemble ...").unwrap();
    let handing_after = |first: Option<usize>, member: usize, patience: usize| {
        let out = dir.join(format!("hand{first:?}-{member}-{patience}"));
        let handover = Handover {
            member,
            patience,
            progress: 0.05,
            first,
            let_go: None,
            far: None,
        };
        Policy::handing_over(&ensemble, handover, &out, "dexcube handover ...").map(|()| out)
    };
    let handing = |member: usize, patience: usize| handing_after(None, member, patience);
    let (together, first, second) = (
        Policy::load(&ensemble, &device).unwrap(),
        Policy::load(&members[0], &device).unwrap(),
        Policy::load(&members[1], &device).unwrap(),
    );
    let hands = Policy::load(&handing(1, 2).unwrap(), &device).unwrap();
    assert_eq!(
        hands.card.metadata["handing_over"],
        ensemble.display().to_string()
    );
    let test = dexcube_env::LayerGoal::square();
    let mut env = PointMassEnv::default();
    let (obs, _) = env.reset(Some(3));
    let (achieved, desired) = (&obs.achieved_goal, &obs.desired_goal);
    assert!(!test.is_success(achieved, desired));
    let (as_ensemble, as_member) = (
        together.act(&obs.observation, desired),
        second.act(&obs.observation, desired),
    );
    let as_first = first.act(&obs.observation, desired);
    assert_ne!(as_ensemble, as_member, "the members differ");
    assert_ne!(as_ensemble, as_first, "the mean is neither member");
    // Member 0 acting alone until it hands over, in place of the mean.
    let falls_back = Policy::load(&handing_after(Some(0), 1, 2).unwrap(), &device).unwrap();
    for (policy, before) in [(&hands, &as_ensemble), (&falls_back, &as_first)] {
        for _episode in 0..2 {
            let mut acting = policy.episode();
            // The cube never moves: the first step is progress, the next two stall.
            for step in 1..=5 {
                let action =
                    acting.act_toward(&obs.observation, desired, || achieved.clone(), &test);
                let (expected, handed) = if step < 3 {
                    (before, false)
                } else {
                    (&as_member, true)
                };
                assert_eq!(&action, expected, "step {step}");
                assert_eq!(acting.handed_over(), handed, "step {step}");
            }
        }
    }
    // Letting go for two steps once handed over: the neutral action, then the member; a
    // single policy may so hand the episode to itself.
    let letting_go = |from: &std::path::Path, member: usize, name: &str| {
        let handover = Handover {
            member,
            patience: 2,
            progress: 0.05,
            first: None,
            let_go: Some(2),
            far: None,
        };
        let out = dir.join(name);
        Policy::handing_over(from, handover, &out, "dexcube handover ...").unwrap();
        Policy::load(&out, &device).unwrap()
    };
    let neutral = vec![0.0; as_member.len()];
    for (policy, before, after) in [
        (letting_go(&ensemble, 1, "let-go"), &as_ensemble, &as_member),
        (
            letting_go(&members[1], 0, "let-go-alone"),
            &as_member,
            &as_member,
        ),
    ] {
        let mut acting = policy.episode();
        for step in 1..=6 {
            let action = acting.act_toward(&obs.observation, desired, || achieved.clone(), &test);
            let expected = match step {
                1 | 2 => before,
                3 | 4 => &neutral,
                _ => after,
            };
            assert_eq!(&action, expected, "step {step}");
        }
    }
    let at_once = Policy::load(&handing(1, 0).unwrap(), &device).unwrap();
    let mut acting = at_once.episode();
    let action = acting.act_toward(&obs.observation, desired, || achieved.clone(), &test);
    assert_eq!(action, as_member, "a patience of 0 is the member alone");
    // A far member takes the stalls at least `beyond` from the goal: every stall with 0, none
    // with a `beyond` past any angle; the rest go to the member.
    let handing_far = |first: Option<usize>, member: usize, beyond: f64| {
        let out = dir.join(format!("far{first:?}-{member}-{beyond}"));
        let far = Some(FarHandover { member, beyond });
        let handover = Handover {
            first,
            far,
            ..hands.card.handover.unwrap()
        };
        Policy::handing_over(&ensemble, handover, &out, "dexcube handover ...").map(|()| out)
    };
    for (beyond, member, expected) in [(0.0, 0, &as_first), (1e9, 1, &as_member)] {
        let policy = Policy::load(&handing_far(None, 0, beyond).unwrap(), &device).unwrap();
        let mut acting = policy.episode();
        for step in 1..=4 {
            let action = acting.act_toward(&obs.observation, desired, || achieved.clone(), &test);
            let expected = if step < 3 { &as_ensemble } else { expected };
            assert_eq!(&action, expected, "beyond {beyond}, step {step}");
        }
        assert_eq!(acting.handed_to(), Some(member), "beyond {beyond}");
    }

    let refusal = |from: &std::path::Path| {
        let handover = hands.card.handover.unwrap();
        let result = Policy::handing_over(from, handover, &dir.join("x"), "");
        result.err().unwrap().to_string()
    };
    assert!(refusal(&dir.join("handNone-1-2")).contains("hands over already"));
    assert!(refusal(&members[1]).contains("single policy, with no member"));
    for (first, member, says) in [
        (None, 2, "2 members (0 to 1), not a member 2"),
        (Some(2), 1, "2 members (0 to 1), not a member 2"),
        (Some(1), 1, "member 1 would hand over to itself"),
    ] {
        let refused = handing_after(first, member, 5).err().unwrap().to_string();
        assert!(refused.contains(says), "{refused}");
    }
    for (first, far, says) in [
        (None, 2, "2 members (0 to 1), not a member 2"),
        (
            None,
            1,
            "member 1 takes the far-off stalls and the others alike",
        ),
        (Some(0), 0, "member 0 would hand over to itself"),
    ] {
        let refused = handing_far(first, far, 0.5).err().unwrap().to_string();
        assert!(refused.contains(says), "{refused}");
    }
}

/// The outputs of `net` on a fixed batch of `inputs`-long rows.
fn outputs_on_a_batch(net: &dexcube_rl::networks::Mlp, inputs: usize) -> Vec<f32> {
    use burn::prelude::*;
    let rows = 16;
    let values: Vec<f32> = (0..rows * inputs)
        .map(|k| ((k * 37 % 23) as f32 - 11.0) / 5.0)
        .collect();
    let batch: Tensor<2> = Tensor::from_data(
        burn::tensor::TensorData::new(values, [rows, inputs]),
        &burn::prelude::Device::flex(),
    );
    net.forward(batch)
        .into_data()
        .convert::<f32>()
        .try_to_vec::<f32>()
        .unwrap()
}

/// A network embedded in a wider one computes what it did, while its new units hold fresh
/// random inputs (so they can learn apart) and zero outgoing weights; networks that cannot
/// grow into the new one are refused, saying why.
#[test]
fn a_network_embedded_in_wider_layers_computes_what_it_did() {
    use dexcube_rl::networks::{Mlp, drawn_from_seed};
    use dexcube_rl::params::{embed_in_wider, read, write};
    let device = burn::prelude::Device::flex();
    let (narrow, wide) = drawn_from_seed(&device, 3, || {
        (
            Mlp::new(6, &[5, 5], 3, &device),
            Mlp::new(6, &[9, 9], 3, &device),
        )
    });
    let embedded = embed_in_wider(&read(&narrow), read(&wide)).unwrap();
    let wide = write(wide, &embedded, |_, given| given.to_vec()).unwrap();
    let (before, after) = (outputs_on_a_batch(&narrow, 6), outputs_on_a_batch(&wide, 6));
    assert!(before.iter().any(|&y| y.abs() > 1e-3), "a batch that tells");
    for (b, a) in before.iter().zip(&after) {
        assert!((b - a).abs() < 1e-5, "{b} became {a}");
    }
    let tensor = |name: &str| embedded.iter().find(|t| t.name == name).unwrap();
    let hidden = tensor("layers.1.weight");
    assert_eq!(hidden.shape, [9, 9]);
    let new_units_in = |r: usize| &hidden.values[r * 9 + 5..(r + 1) * 9];
    assert!(
        (0..9).all(|r| new_units_in(r).iter().any(|&w| w != 0.0)),
        "a new unit takes fresh inputs from every unit before it"
    );
    let out = tensor("layers.2.weight");
    assert!(
        out.values[5 * 3..].iter().all(|&w| w == 0.0),
        "the new units have no say in the output yet"
    );
    let same = embed_in_wider(&read(&narrow), read(&narrow)).unwrap();
    assert_eq!(
        same,
        read(&narrow),
        "a network of the same widths is taken as saved"
    );
    let err = embed_in_wider(&read(&wide), read(&narrow)).unwrap_err();
    assert!(err.contains("cannot grow"), "{err}");
    let deeper = Mlp::new(6, &[5, 5, 5], 3, &device);
    let err = embed_in_wider(&read(&narrow), read(&deeper)).unwrap_err();
    assert!(
        err.contains("only the hidden layers' width can grow"),
        "{err}"
    );
}

/// A run of wider hidden layers warm-starts from a narrower run: the actor and both critics
/// carry the saved weights in their first units, the card says the run's widths, and a
/// narrower run is refused.
#[test]
fn a_warm_start_onto_wider_hidden_layers_embeds_the_saved_networks() {
    let (source, dir, warm, frozen) = warm_start_from_a_new_run("dexcube-rl-wider");
    let wider = DdpgHerConfig {
        hidden: vec![48, 48],
        ..frozen
    };
    let run = train(PointMassEnv::default, wider, &warm).unwrap();
    for (k, name) in ["actor", "critic"].into_iter().enumerate() {
        let saved = dexcube_rl::checkpoint::load_tensors(
            &source.join(format!("checkpoint/{name}.safetensors")),
        )
        .unwrap();
        let now = &run.agent.networks()[k];
        let middle = |set: &[NamedTensor]| {
            set.iter()
                .find(|t| t.name == "layers.1.weight")
                .unwrap()
                .clone()
        };
        let (saved, now) = (middle(&saved), middle(now));
        assert_eq!(now.shape, [48, 48], "{name}");
        for r in 0..48 {
            let kept = &now.values[r * 48..r * 48 + 32];
            if r < 32 {
                assert_eq!(kept, &saved.values[r * 32..(r + 1) * 32], "{name} row {r}");
            } else {
                assert!(kept.iter().all(|&w| w == 0.0), "{name} row {r}");
            }
        }
    }
    let card: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("policy.json")).unwrap()).unwrap();
    assert_eq!(card["config"]["hidden"], serde_json::json!([48, 48]));
    let narrower = DdpgHerConfig {
        hidden: vec![16, 16],
        ..config()
    };
    let err = train(PointMassEnv::default, narrower, &warm).err().unwrap();
    assert!(err.to_string().contains("cannot grow"), "{err}");
}
