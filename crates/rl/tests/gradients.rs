//! burn's gradients through the networks against finite differences, and the two target
//! network pitfalls of DDPG on burn: targets must never track gradients, and training the
//! online networks must keep changing them after the targets are made.

use burn::prelude::*;
use burn::tensor::TensorData;
use dexcube_rl::agent::Batch;
use dexcube_rl::networks::Mlp;
use dexcube_rl::params;
use dexcube_rl::{Agent, DdpgHerConfig, Dims};

#[test]
fn autodiff_matches_finite_differences() {
    let device = Device::flex();
    device.seed(7);
    let net = Mlp::new(3, &[8, 8], 2, &device.clone().autodiff());
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

#[test]
fn targets_follow_by_polyak_and_never_stop_the_online_networks_learning() {
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
    let mut agent = Agent::new(dims, config, &Device::flex(), 1);
    let batch = Batch {
        len: 8,
        observation: (0..32).map(|i| (i as f64 * 0.37).sin()).collect(),
        goal: (0..16).map(|i| (i as f64 * 0.11).cos()).collect(),
        action: (0..16).map(|i| ((i as f32) * 0.2).sin()).collect(),
        reward: vec![-1.0; 8],
        next_observation: (0..32).map(|i| (i as f64 * 0.41).cos()).collect(),
    };
    let [actor0, _, target0, _] = agent.networks();
    for _ in 0..3 {
        for _ in 0..5 {
            agent.train(&batch);
        }
        agent.end_cycle();
    }
    let [actor1, critic1, target1, target_critic1] = agent.networks();
    let moved = |a: &[params::NamedTensor], b: &[params::NamedTensor]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| {
                x.values
                    .iter()
                    .zip(&y.values)
                    .map(|(p, q)| (p - q).abs())
                    .sum::<f32>()
            })
            .sum::<f32>()
    };
    assert!(
        moved(&actor0, &actor1) > 0.0,
        "the actor still learns after its target was made"
    );
    assert!(
        moved(&target0, &target1) > 0.0,
        "the target moved towards it"
    );
    assert!(moved(&target1, &actor1) > 0.0, "but only part of the way");
    // The targets are plain-device snapshots: no parameter of theirs requires a gradient.
    assert!(!critic1.is_empty() && !target_critic1.is_empty());
    assert!(agent.targets_track_no_gradients());
}
