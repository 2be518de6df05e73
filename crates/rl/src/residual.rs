//! Residual policy learning (Silver et al. 2018; Johannink et al. 2019): a small correction
//! learned on top of a fixed policy that already works, rather than a policy from scratch or
//! a fine-tune of one. The base acts as its card says (an ensemble led on and handing over,
//! say); the residual sees the observation and the base's action, and the action taken is
//! the base's plus `scale` times the residual's, clipped to [-1, 1].
//!
//! [`ResidualEnv`] trains one: it wraps an environment so that the learner's action is the
//! residual and its observation carries the base's action, which is all DDPG + HER need. A
//! residual actor whose output starts at zero ([`crate::TrainOptions::zero_output`]) begins
//! acting exactly as the base. [`crate::Policy::with_residual`] then ships the base and the
//! trained residual as one policy, which acts through [`crate::Policy::episode`] as the
//! environment acted in training.

use std::sync::Arc;

use dexcube_env::{Goal, GoalEnv, Info, Observation, Spaces, Transition};
use serde::{Deserialize, Serialize};

use crate::policy::{EpisodeMemory, Policy};

/// How a residual joins its base: `scale` times its action is added to the base's. A
/// training run records it in its metadata (`residual`), and a shipped policy on its card.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ResidualSetting {
    /// The base policy, as given to the training run.
    pub of: std::path::PathBuf,
    pub scale: f64,
}

/// The action taken: `base` plus `scale` times `residual`, each component clipped to [-1, 1].
pub fn residual_action(base: &[f64], residual: &[f64], scale: f64) -> Vec<f64> {
    base.iter()
        .zip(residual)
        .map(|(b, r)| (b + scale * r).clamp(-1.0, 1.0))
        .collect()
}

/// Why `scale` cannot scale a residual, if it cannot: it must lie in (0, 1].
pub fn check_scale(scale: f64) -> Result<(), String> {
    if scale > 0.0 && scale <= 1.0 {
        Ok(())
    } else {
        Err(format!(
            "a residual's scale must be above 0 and at most 1 (the whole action range), not \
             {scale}"
        ))
    }
}

/// An environment in which the action is a residual on top of `base`: the observation is the
/// wrapped one followed by the base's action for it, and a step takes
/// [`residual_action`]. The base acts through one [`Policy::episode`] per episode, as it would
/// deployed, so its goal lead, handover and gestures all apply.
pub struct ResidualEnv<E> {
    env: E,
    base: Arc<Policy>,
    scale: f64,
    goal: Arc<dyn Goal>,
    /// What the base keeps through the episode (its handover's watch, its step count).
    memory: EpisodeMemory,
    /// The base's action for the latest observation.
    base_action: Vec<f64>,
}

impl<E: GoalEnv> ResidualEnv<E> {
    /// `env` with `base` acting in it and the learner's action added at `scale`. Refuses a
    /// base whose sizes are not `env`'s, a scale outside (0, 1], and a base with a residual
    /// of its own.
    pub fn new(env: E, base: Arc<Policy>, scale: f64) -> Result<ResidualEnv<E>, String> {
        check_scale(scale)?;
        let (spaces, dims) = (env.spaces(), base.card.dims);
        if (spaces.observation, spaces.goal, spaces.action)
            != (dims.observation, dims.goal, dims.action)
        {
            return Err(format!(
                "the base policy takes {dims:?}, the environment gives {spaces:?}: train the \
                 residual on the environment (view, success test) its base was trained on"
            ));
        }
        if base.card.residual.is_some() {
            return Err(
                "the base has a residual already: train on the policy it was made \
                        from, or make it the base of none"
                    .into(),
            );
        }
        let goal = env.goal();
        // The episode's memory and the base's first action come with the first reset.
        Ok(ResidualEnv {
            memory: EpisodeMemory::default(),
            env,
            base,
            scale,
            goal,
            base_action: Vec::new(),
        })
    }

    /// The base's action for `observation`, kept for the next step, appended to it.
    fn with_base_action(&mut self, mut observation: Observation) -> Observation {
        let memory = std::mem::take(&mut self.memory);
        let mut acting = self.base.resume(memory);
        let achieved = || observation.achieved_goal.clone();
        self.base_action = acting.act_toward(
            &observation.observation,
            &observation.desired_goal,
            achieved,
            self.goal.as_ref(),
        );
        self.memory = acting.into_memory();
        observation.observation.extend(&self.base_action);
        observation
    }
}

impl<E: GoalEnv> GoalEnv for ResidualEnv<E> {
    fn spaces(&self) -> Spaces {
        let spaces = self.env.spaces();
        Spaces {
            observation: spaces.observation + spaces.action,
            ..spaces
        }
    }

    fn goal(&self) -> Arc<dyn Goal> {
        self.goal.clone()
    }

    fn reset(&mut self, seed: Option<u64>) -> (Observation, Info) {
        let (observation, info) = self.env.reset(seed);
        self.memory = self.base.episode().into_memory();
        (self.with_base_action(observation), info)
    }

    fn step(&mut self, residual: &[f64]) -> Transition {
        let action = residual_action(&self.base_action, residual, self.scale);
        let mut transition = self.env.step(&action);
        transition.observation = self.with_base_action(transition.observation);
        transition
    }
}
