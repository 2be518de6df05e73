//! burn's gradients through the networks against finite differences, and the two target
//! network pitfalls of DDPG on burn: targets must never track gradients, and training the
//! online networks must keep changing them after the targets are made.

use burn::prelude::*;
use burn::tensor::TensorData;
use dexcube_rl::agent::Batch;
use dexcube_rl::networks::{Mlp, drawn_from_seed};
use dexcube_rl::params;
use dexcube_rl::{Agent, DdpgHerConfig, Dims, Learners};

#[test]
fn autodiff_matches_finite_differences() {
    let device = Device::flex();
    let net = drawn_from_seed(&device, 7, || {
        Mlp::new(3, &[8, 8], 2, &device.clone().autodiff())
    });
    let loss_at = |x: &[f32]| -> (f64, Vec<f64>) {
        let input: Tensor<2> = Tensor::from_data(
            TensorData::new(x.to_vec(), [1, 3]),
            &device.clone().autodiff(),
        )
        .require_grad();
        let loss = net.forward(input.clone()).tanh().powi_scalar(2).sum();
        let value = loss.to_data().convert::<f64>().try_to_vec::<f64>().unwrap()[0];
        let grads = loss.backward();
        let grad = input
            .grad(&grads)
            .unwrap()
            .into_data()
            .convert::<f64>()
            .try_to_vec::<f64>()
            .unwrap();
        (value, grad)
    };
    let x = [0.3f32, -0.7, 1.1];
    let (_, analytic) = loss_at(&x);
    for k in 0..3 {
        let h = 1e-2f32;
        let (mut up, mut down) = (x, x);
        up[k] += h;
        down[k] -= h;
        let numeric = (loss_at(&up).0 - loss_at(&down).0) / (2.0 * h as f64);
        assert!(
            (numeric - analytic[k]).abs() < 1e-2 * (1.0 + numeric.abs()),
            "d/dx{k}: {numeric} vs {}",
            analytic[k]
        );
    }
}

/// An agent with 4 observations, 2 goal and 2 action dimensions, two hidden layers of 16,
/// and batches of 8.
fn small_agent(seed: u64) -> (Agent, DdpgHerConfig) {
    let dims = Dims {
        observation: 4,
        goal: 2,
        action: 2,
    };
    let config = DdpgHerConfig {
        hidden: vec![16, 16],
        batch_size: 8,
        ..DdpgHerConfig::default()
    };
    (
        Agent::new(dims, config.clone(), &Device::flex(), seed),
        config,
    )
}

/// Eight made-up transitions for a [`small_agent`].
fn eight_transitions() -> Batch {
    Batch {
        len: 8,
        observation: (0..32).map(|i| (i as f64 * 0.37).sin()).collect(),
        goal: (0..16).map(|i| (i as f64 * 0.11).cos()).collect(),
        action: (0..16).map(|i| ((i as f32) * 0.2).sin()).collect(),
        reward: vec![-1.0; 8],
        next_observation: (0..32).map(|i| (i as f64 * 0.41).cos()).collect(),
        terminal: vec![0.0; 8],
    }
}

#[test]
fn a_critic_only_step_leaves_the_actor_as_it_was_and_trains_the_critic() {
    let (mut agent, _) = small_agent(4);
    let batch = eight_transitions();
    let [actor0, critic0, ..] = agent.networks();
    for _ in 0..5 {
        agent.train(&batch, Learners::CriticOnly);
    }
    agent.end_cycle();
    let [actor1, critic1, target_actor1, _] = agent.networks();
    assert_eq!(
        params::l1_distance(&actor0, &actor1),
        0.0,
        "the actor is held"
    );
    // A Polyak blend of equal weights returns them, up to rounding.
    assert!(
        params::l1_distance(&actor1, &target_actor1) < 1e-5,
        "so its target stays on it"
    );
    assert!(
        params::l1_distance(&critic0, &critic1) > 0.0,
        "the critic learns"
    );
    // The same steps with both learners do move the actor.
    agent.train(&batch, Learners::ActorAndCritic);
    agent.end_cycle();
    assert!(params::l1_distance(&actor1, &agent.networks()[0]) > 0.0);
}

#[test]
fn targets_follow_by_polyak_and_never_stop_the_online_networks_learning() {
    let (mut agent, _) = small_agent(1);
    let batch = eight_transitions();
    let [actor0, _, target0, _] = agent.networks();
    for _ in 0..3 {
        for _ in 0..5 {
            agent.train(&batch, Learners::ActorAndCritic);
        }
        agent.end_cycle();
    }
    let [actor1, critic1, target1, target_critic1] = agent.networks();
    assert!(
        params::l1_distance(&actor0, &actor1) > 0.0,
        "the actor still learns after its target was made"
    );
    assert!(
        params::l1_distance(&target0, &target1) > 0.0,
        "the target moved towards it"
    );
    assert!(
        params::l1_distance(&target1, &actor1) > 0.0,
        "but only part of the way"
    );
    // The targets are plain-device snapshots: no parameter of theirs requires a gradient.
    assert!(!critic1.is_empty() && !target_critic1.is_empty());
    assert!(agent.targets_track_no_gradients());
}

#[test]
fn a_dropped_object_is_worth_its_drop_cost_and_other_steps_bootstrap() {
    let (agent, config) = small_agent(2);
    let n = 6;
    let batch = Batch {
        len: n,
        observation: (0..n * 4).map(|i| (i as f64 * 0.3).sin()).collect(),
        goal: (0..n * 2).map(|i| (i as f64 * 0.7).cos()).collect(),
        action: vec![0.1; n * 2],
        reward: vec![-1.0, 0.0, -1.0, 0.0, -1.0, 0.0],
        next_observation: (0..n * 4).map(|i| (i as f64 * 0.5).cos()).collect(),
        terminal: vec![1.0, 1.0, 0.0, 0.0, 0.0, 0.0],
    };
    let y = agent.td_targets(&batch);
    let floor = -config.clip_return() as f32;
    assert_eq!(
        &y[..2],
        &[floor, floor],
        "a drop fails forever, whatever the goal"
    );
    // A fresh critic's Q' is near 0, so a bootstrapped target is near the reward.
    for (i, &r) in batch.reward.iter().enumerate().skip(2) {
        assert!((y[i] - r).abs() < 0.5, "row {i}: {} from reward {r}", y[i]);
    }
    // A drop made to cost three floors is worth exactly that; the other targets are unmoved.
    let costly = DdpgHerConfig {
        drop_cost: 3.0,
        ..config
    };
    let mut dearer = Agent::new(agent.dims, costly, &Device::flex(), 2);
    dearer.load_networks(&agent.networks()).unwrap();
    let y3 = dearer.td_targets(&batch);
    assert_eq!(&y3[..2], &[3.0 * floor, 3.0 * floor]);
    assert_eq!(&y3[2..], &y[2..]);
}

#[test]
fn twin_critics_take_the_smaller_target_and_the_actor_learns_every_second_step() {
    let (mut ddpg, config) = small_agent(5);
    let mut td3 = Agent::new(ddpg.dims, config.with_td3(), &Device::flex(), 5);
    let batch = eight_transitions();
    // DDPG with TD3's actor and first critic: the targets of one critic.
    ddpg.load_networks(&td3.networks()).unwrap();
    let (single, twin) = (ddpg.td_targets(&batch), td3.td_targets(&batch));
    assert!(
        single.iter().zip(&twin).all(|(s, t)| t <= s),
        "{twin:?} never above {single:?}"
    );
    assert!(
        single.iter().zip(&twin).any(|(s, t)| t < s),
        "and below it where the second critic is lower: {twin:?} against {single:?}"
    );
    let [actor0, critic0, ..] = td3.networks();
    let [second0, _] = td3.twin_networks().expect("a second critic");
    td3.train(&batch, Learners::ActorAndCritic);
    let [actor1, critic1, ..] = td3.networks();
    let [second1, _] = td3.twin_networks().unwrap();
    assert_eq!(
        params::l1_distance(&actor0, &actor1),
        0.0,
        "the actor waits"
    );
    assert!(
        params::l1_distance(&critic0, &critic1) > 0.0,
        "critic 1 learns"
    );
    assert!(
        params::l1_distance(&second0, &second1) > 0.0,
        "critic 2 learns"
    );
    td3.train(&batch, Learners::ActorAndCritic);
    assert!(
        params::l1_distance(&actor1, &td3.networks()[0]) > 0.0,
        "and learns on the second step"
    );
    td3.end_cycle();
    assert!(td3.targets_track_no_gradients());
    assert!(ddpg.twin_networks().is_none(), "DDPG has one critic");
}
