//! A trained policy as shipped: the actor's weights (`NAME.safetensors`) and a JSON beside it
//! (`NAME.json`) with the sizes, the normalisers, the training configuration and whatever
//! metrics the trainer recorded. It acts without the critic or any optimiser state.

use std::path::{Path, PathBuf};

use burn::prelude::*;
use serde::{Deserialize, Serialize};

use crate::agent::{Agent, Dims, network_inputs};
use crate::checkpoint::{self, CheckpointError};
use crate::config::DdpgHerConfig;
use crate::networks::Mlp;
use crate::normalizer::Normalizer;
use crate::params::{self, NamedTensor};

/// Everything about a policy but its weights.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PolicyCard {
    pub dims: Dims,
    pub config: DdpgHerConfig,
    pub observation_norm: Normalizer,
    pub goal_norm: Normalizer,
    /// Free-form facts: environment, seed, steps, wall time, evaluation.
    pub metadata: serde_json::Value,
}

pub struct Policy {
    pub card: PolicyCard,
    actor: Mlp,
    device: Device,
}

/// `prefix.safetensors` and `prefix.json`.
pub fn policy_paths(prefix: &Path) -> (PathBuf, PathBuf) {
    (
        prefix.with_extension("safetensors"),
        prefix.with_extension("json"),
    )
}

impl Policy {
    /// Saves an agent's actor as a policy at each of `prefixes` (the latest, the best, a
    /// snapshot: one read of the weights serves them all).
    pub fn save(
        agent: &Agent,
        prefixes: &[PathBuf],
        metadata: serde_json::Value,
    ) -> Result<(), CheckpointError> {
        let card = PolicyCard {
            dims: agent.dims,
            config: agent.config.clone(),
            observation_norm: agent.observation_norm.clone(),
            goal_norm: agent.goal_norm.clone(),
            metadata,
        };
        let actor = agent.actor_params();
        for prefix in prefixes {
            let (weights, card_path) = policy_paths(prefix);
            checkpoint::save_tensors(&weights, &actor)?;
            checkpoint::save_json(&card_path, &card)?;
        }
        Ok(())
    }

    /// Writes at `out` the weight average of the policies at `members` (stochastic weight
    /// averaging over one run's snapshots): each actor weight is the mean of the members',
    /// and the normalisers pool the members' statistics. The members must share the network
    /// and the environment's sizes. The card keeps the first member's configuration, label and
    /// environment, and records the members and `command`, the command that averaged them.
    pub fn average(members: &[PathBuf], out: &Path, command: &str) -> Result<(), CheckpointError> {
        let mut loaded = Vec::with_capacity(members.len());
        for member in members {
            let (weights, card_path) = policy_paths(member);
            let card: PolicyCard = checkpoint::load_json(&card_path)?;
            let mut tensors = checkpoint::load_tensors(&weights)?;
            tensors.sort_by(|a, b| a.name.cmp(&b.name));
            loaded.push((weights, card, tensors));
        }
        let Some(((_, first_card, first), rest)) = loaded.split_first() else {
            return Err(CheckpointError::Mismatch {
                path: out.to_path_buf(),
                message: "no policies to average".to_string(),
            });
        };
        // The tensors' names and shapes are the network's sizes; the normalisers, pooled
        // below, check the environment's.
        fn layout(tensors: &[NamedTensor]) -> Vec<(&str, &[usize])> {
            tensors
                .iter()
                .map(|t| (t.name.as_str(), t.shape.as_slice()))
                .collect()
        }
        let first_layout = layout(first);
        let mut mean = first.clone();
        for (weights, _, tensors) in rest {
            if layout(tensors) != first_layout {
                return Err(CheckpointError::Mismatch {
                    path: weights.clone(),
                    message: format!("other network sizes than {}", members[0].display()),
                });
            }
            for (total, tensor) in mean.iter_mut().zip(tensors) {
                for (t, v) in total.values.iter_mut().zip(&tensor.values) {
                    *t += v;
                }
            }
        }
        let scale = 1.0 / members.len() as f32;
        for tensor in &mut mean {
            tensor.values.iter_mut().for_each(|v| *v *= scale);
        }
        let pooled = |pick: fn(&PolicyCard) -> &Normalizer| {
            let members: Vec<&Normalizer> = loaded.iter().map(|(_, card, _)| pick(card)).collect();
            Normalizer::pooled(&members).ok_or_else(|| CheckpointError::Mismatch {
                path: out.to_path_buf(),
                message: "the members' normalisers differ in size or settings".to_string(),
            })
        };
        let head = &first_card.metadata;
        let card = PolicyCard {
            observation_norm: pooled(|c| &c.observation_norm)?,
            goal_norm: pooled(|c| &c.goal_norm)?,
            metadata: serde_json::json!({
                "label": head["label"],
                "environment": head["environment"],
                "averaged": members,
                "command": command,
            }),
            ..first_card.clone()
        };
        let (weights, card_path) = policy_paths(out);
        checkpoint::save_tensors(&weights, &mean)?;
        checkpoint::save_json(&card_path, &card)
    }

    /// Loads the policy at `prefix` onto `device`.
    pub fn load(prefix: &Path, device: &Device) -> Result<Policy, CheckpointError> {
        let (weights, card_path) = policy_paths(prefix);
        let card: PolicyCard = checkpoint::load_json(&card_path)?;
        let tensors = checkpoint::load_tensors(&weights)?;
        let Dims {
            observation,
            goal,
            action,
        } = card.dims;
        let actor = Mlp::new(observation + goal, &card.config.hidden, action, device);
        let actor = params::write(actor, &tensors, |_, given| given.to_vec()).map_err(|e| {
            CheckpointError::Mismatch {
                path: weights.clone(),
                message: e.to_string(),
            }
        })?;
        Ok(Policy {
            card,
            actor,
            device: device.clone(),
        })
    }

    /// The deterministic action for one observation and goal.
    pub fn act(&self, observation: &[f64], goal: &[f64]) -> Vec<f64> {
        let card = &self.card;
        let x = network_inputs(
            &card.observation_norm,
            &card.goal_norm,
            observation,
            goal,
            1,
            &self.device,
        );
        let out = self.actor.forward(x).tanh().into_data().convert::<f64>();
        out.try_to_vec::<f64>().unwrap_or_default()
    }
}
