//! Acting with the critic's help: the actor proposes an action, and the action taken is the
//! one of a few nearby that a run's critics value most (the smaller of TD3's two critics'
//! values, or the one critic's under DDPG). The candidates are the actor's action itself and
//! that action moved by `spread` along each of a fixed set of directions, drawn once from a
//! seed, so a guided policy acts deterministically.
//!
//! The critics are a training run's (`checkpoint/critic.safetensors`, and `critic2` with
//! TD3's options), read with the normalisers that run's `state.json` keeps, and they ship
//! inside the guided policy's own files ([`crate::Policy::guide`]), so it loads and acts like
//! any other policy.

use std::path::{Path, PathBuf};

use burn::prelude::*;
use burn::tensor::TensorData;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::agent::{Dims, input_row_into};
use crate::checkpoint::CheckpointError;
use crate::networks::Mlp;
use crate::normalizer::Normalizer;
use crate::params::{self, NamedTensor};
use crate::train;
use dexcube_env::random::standard_normal;

/// A guide as a policy's card keeps it; its critics' weights are the policy's tensors named
/// `guide.critic{j}.…`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GuideCard {
    /// The training run the critics were taken from.
    pub run: PathBuf,
    pub hidden: Vec<usize>,
    /// 1 under DDPG, 2 with TD3's twin critics.
    pub critics: usize,
    pub observation_norm: Normalizer,
    pub goal_norm: Normalizer,
    /// How many actions beside the actor's the critics weigh, how far from it, and the seed
    /// the directions are drawn from.
    pub candidates: usize,
    pub spread: f64,
    pub seed: u64,
}

/// The tensor-name prefix of a guide's `j`-th critic.
fn critic_prefix(j: usize) -> String {
    format!("guide.critic{j}.")
}

/// The critics of the training run in `run` as a guide weighing `candidates` actions beside
/// the actor's, each `spread` times a standard normal direction drawn from `seed`: the card,
/// the sizes the critics take, and their weights named as a policy stores them.
pub(crate) fn read_run(
    run: &Path,
    (candidates, spread, seed): (usize, f64, u64),
) -> Result<(GuideCard, Dims, Vec<NamedTensor>), CheckpointError> {
    let read = train::read_critics(run)?;
    let critics = read.critics.len();
    let tensors = read
        .critics
        .into_iter()
        .enumerate()
        .flat_map(|(j, critic)| params::prefixed(critic, &critic_prefix(j)))
        .collect();
    let card = GuideCard {
        run: run.to_path_buf(),
        hidden: read.hidden,
        critics,
        observation_norm: read.observation_norm,
        goal_norm: read.goal_norm,
        candidates,
        spread,
        seed,
    };
    Ok((card, read.dims, tensors))
}

/// A run's critics, and the candidates they choose among.
pub struct CriticGuide {
    critics: Vec<Mlp>,
    action: usize,
    observation_norm: Normalizer,
    goal_norm: Normalizer,
    /// Unit-variance directions, one row per candidate beside the actor's own action.
    directions: Vec<Vec<f64>>,
    spread: f64,
    device: Device,
}

impl CriticGuide {
    /// The guide `card` describes for a policy of sizes `dims`, its critics from the policy's
    /// `tensors` (stored at `path`).
    pub(crate) fn build(
        card: &GuideCard,
        dims: Dims,
        tensors: &[NamedTensor],
        path: &Path,
        device: &Device,
    ) -> Result<CriticGuide, CheckpointError> {
        let input = dims.observation + dims.goal + dims.action;
        let critics = (0..card.critics)
            .map(|j| {
                let own = params::under_prefix(tensors, &critic_prefix(j));
                let critic = Mlp::new(input, &card.hidden, 1, device);
                params::write(critic, &own, |_, given| given.to_vec()).map_err(|e| {
                    CheckpointError::Mismatch {
                        path: path.to_path_buf(),
                        message: format!("its guide's critic {j}: {e}"),
                    }
                })
            })
            .collect::<Result<_, _>>()?;
        let mut rng = ChaCha8Rng::seed_from_u64(card.seed);
        let directions = (0..card.candidates)
            .map(|_| {
                (0..dims.action)
                    .map(|_| standard_normal(&mut rng))
                    .collect()
            })
            .collect();
        Ok(CriticGuide {
            critics,
            action: dims.action,
            observation_norm: card.observation_norm.clone(),
            goal_norm: card.goal_norm.clone(),
            directions,
            spread: card.spread,
            device: device.clone(),
        })
    }

    /// `proposed` and the candidates around it, each moved along one of the directions and
    /// clipped to the action range.
    fn candidates(&self, proposed: Vec<f64>) -> Vec<Vec<f64>> {
        let moved: Vec<Vec<f64>> = self
            .directions
            .iter()
            .map(|direction| {
                proposed
                    .iter()
                    .zip(direction)
                    .map(|(a, d)| (a + self.spread * d).clamp(-1.0, 1.0))
                    .collect()
            })
            .collect();
        std::iter::once(proposed).chain(moved).collect()
    }

    /// Of `proposed` and the candidates around it, the action the critics value most for
    /// this observation and goal.
    pub fn choose(&self, observation: &[f64], goal: &[f64], proposed: Vec<f64>) -> Vec<f64> {
        let mut actions = self.candidates(proposed);
        // The observation and goal are normalised once; every candidate shares them.
        let mut row = Vec::new();
        input_row_into(
            (&self.observation_norm, &self.goal_norm),
            observation,
            goal,
            &mut row,
        );
        let width = row.len() + self.action;
        let mut inputs = Vec::with_capacity(actions.len() * width);
        for action in &actions {
            inputs.extend_from_slice(&row);
            inputs.extend(action.iter().map(|&a| a as f32));
        }
        let shape = [actions.len(), width];
        let input = Tensor::from_data(TensorData::new(inputs, shape), &self.device);
        let mut q = self.critics[0].forward(input.clone());
        for critic in &self.critics[1..] {
            q = q.min_pair(critic.forward(input.clone()));
        }
        let values = q
            .into_data()
            .convert::<f64>()
            .try_to_vec::<f64>()
            .unwrap_or_default();
        let best = values
            .iter()
            .enumerate()
            .fold(0, |best, (i, v)| if *v > values[best] { i } else { best });
        actions.swap_remove(best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ACTION: usize = 3;

    /// A critic with no hidden layer whose value is `sign` times the sum of the action.
    fn linear_critic(sign: f32, device: &Device) -> Mlp {
        let critic = Mlp::new(1 + 1 + ACTION, &[], 1, device);
        let weights: Vec<NamedTensor> = params::read(&critic)
            .into_iter()
            .map(|t| {
                let values = match t.name.ends_with("weight") {
                    // Rows are inputs: the observation and goal, then the action.
                    true => (0..t.values.len())
                        .map(|i| if i >= 2 { sign } else { 0.0 })
                        .collect(),
                    false => vec![0.0; t.values.len()],
                };
                NamedTensor { values, ..t }
            })
            .collect();
        params::write(critic, &weights, |_, given| given.to_vec()).unwrap()
    }

    fn guide(signs: &[f32], candidates: usize) -> CriticGuide {
        let device = Device::flex();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        CriticGuide {
            critics: signs.iter().map(|&s| linear_critic(s, &device)).collect(),
            action: ACTION,
            observation_norm: Normalizer::new(1, 0.01, 5.0, 200.0),
            goal_norm: Normalizer::new(1, 0.01, 5.0, 200.0),
            directions: (0..candidates)
                .map(|_| (0..ACTION).map(|_| standard_normal(&mut rng)).collect())
                .collect(),
            spread: 0.3,
            device,
        }
    }

    fn sum(action: &[f64]) -> f64 {
        action.iter().sum()
    }

    const PROPOSED: [f64; ACTION] = [0.2, -0.4, 0.9];

    #[test]
    fn without_candidates_the_actor_s_action_is_taken() {
        let chosen = guide(&[1.0], 0).choose(&[0.5], &[0.1], PROPOSED.to_vec());
        assert_eq!(chosen, PROPOSED.to_vec());
    }

    #[test]
    fn the_candidate_the_critic_values_most_is_taken() {
        let guide = guide(&[1.0], 16);
        let chosen = guide.choose(&[0.5], &[0.1], PROPOSED.to_vec());
        let best = guide
            .candidates(PROPOSED.to_vec())
            .into_iter()
            .max_by(|a, b| sum(a).total_cmp(&sum(b)))
            .unwrap();
        assert!(
            sum(&best) > sum(&PROPOSED),
            "some candidate is valued higher"
        );
        assert!((sum(&chosen) - sum(&best)).abs() < 1e-5);
        assert!(chosen.iter().all(|a| a.abs() <= 1.0));
    }

    #[test]
    fn with_two_critics_the_smaller_value_decides() {
        // One critic values the sum, the other its negation: the smaller of the two is
        // -|sum|, so the candidate with the sum nearest zero wins.
        let guide = guide(&[1.0, -1.0], 16);
        let chosen = guide.choose(&[0.5], &[0.1], PROPOSED.to_vec());
        let nearest = guide
            .candidates(PROPOSED.to_vec())
            .into_iter()
            .min_by(|a, b| sum(a).abs().total_cmp(&sum(b).abs()))
            .unwrap();
        assert!((sum(&chosen) - sum(&nearest)).abs() < 1e-5);
        assert!(sum(&chosen).abs() < sum(&PROPOSED).abs());
    }
}
