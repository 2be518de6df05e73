//! The DDPG agent (Lillicrap et al. 2016) as HER baselines run it: a deterministic actor
//! π(o, g) = tanh(MLP), a critic Q(o, g, u), target copies of both updated by polyak
//! averaging once per cycle, and inputs normalised by running statistics.
//!
//! One optimisation step on a batch (o, g, u, r, o'):
//! - target   y = clip(r + γ·Q'(o', g, π'(o', g)), -c/(1-γ), 0), no gradient; where o' ended
//!   its episode in an absorbing failure (the object dropped), it fails forever after and
//!   y = -c/(1-γ), whatever the goal, with c the drop's cost (`DdpgHerConfig::drop_cost`, 1
//!   in DDPG: the floor, missing for ever). Bootstrapping from a state that no stored transition
//!   starts from would make a drop look as good as the critic's guess about it;
//! - critic   minimise mean (Q(o, g, u) - y)²;
//! - actor    minimise -mean Q(o, g, π(o, g)) + action_l2 · mean π(o, g)²,
//!   and, when fine-tuning with an anchor, + anchor · mean (π(o, g) - π₀(o, g))², where π₀
//!   is the actor as it was loaded, with the normalisers it was loaded with (fixed, so it
//!   acts as it did however the run's statistics move; `DdpgHerConfig::anchor`, 0 in DDPG);
//!
//! both gradients taken from the same forward pass, as baselines does. Target networks live
//! on the plain (non-autodiff) device, so their updates can never grow an autodiff graph.
//!
//! With TD3's options (`DdpgHerConfig::with_td3`; Fujimoto et al. 2018) a second critic learns
//! beside the first on the same targets, y takes the smaller of the two target critics' values
//! at a target action smoothed by clipped Gaussian noise, and the actor (still along the first
//! critic) learns on every `policy_delay`-th step only.

use burn::module::{Module, ModuleMapper, ModuleVisitor, Param, ParamId};
use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer, OptimizerRecord};
use burn::prelude::*;
use burn::tensor::TensorData;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::config::DdpgHerConfig;
use crate::networks::{Mlp, drawn_from_seed};
use crate::normalizer::Normalizer;
use crate::params;
use dexcube_env::random::standard_normal;

/// Sizes the agent is built for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Dims {
    pub observation: usize,
    pub goal: usize,
    pub action: usize,
}

/// A batch of transitions, row-major, raw (unnormalised).
#[derive(Clone, Debug, Default)]
pub struct Batch {
    pub len: usize,
    pub observation: Vec<f64>,
    pub goal: Vec<f64>,
    pub action: Vec<f32>,
    pub reward: Vec<f32>,
    pub next_observation: Vec<f64>,
    /// 1 where `next_observation` ended its episode in an absorbing failure, else 0.
    pub terminal: Vec<f32>,
}

/// Which networks a training step updates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Learners {
    /// DDPG's step: the critic, then the actor along the critic's gradient.
    ActorAndCritic,
    /// The critic alone, the actor kept as it is: a warm start onto another object or test
    /// lets the critic learn the new values from the loaded actor's experience before those
    /// values steer the actor.
    CriticOnly,
}

/// The actor a fine-tuning run is held near, as saved: its weights and the normalisers it
/// was loaded with.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedAnchor {
    pub actor: Vec<params::NamedTensor>,
    pub observation_norm: Normalizer,
    pub goal_norm: Normalizer,
}

/// The anchor as the actor's loss uses it: its network built (plain device), and the
/// normalisers it reads its inputs through.
struct Anchor {
    actor: Mlp,
    observation_norm: Normalizer,
    goal_norm: Normalizer,
}

/// TD3's second critic, with its target and optimiser.
struct TwinCritic {
    critic: Mlp,
    target: Mlp,
    optimizer: ModuleOptimizer,
}

/// The learner's state beside its networks and normalisers, as a checkpoint keeps it so that a
/// resumed run goes on exactly as an uninterrupted one would: each optimiser's moments, the
/// optimisation steps taken (which time TD3's delayed actor) and where the stream of TD3's
/// smoothing noise stands.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LearnerState {
    pub steps: usize,
    /// The smoothing noise generator's word position (a decimal `u128`).
    pub smoothing_position: String,
    /// For each optimised network (actor, critic, then TD3's second critic), the ids its
    /// parameters had, in visiting order: its optimiser's moments are keyed by them.
    pub parameter_ids: Vec<Vec<u64>>,
}

/// What one optimisation step measured.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepStats {
    pub critic_loss: f64,
    pub actor_loss: f64,
    pub mean_q: f64,
}

pub struct Agent {
    pub config: DdpgHerConfig,
    pub dims: Dims,
    device: Device,
    plain: Device,
    actor: Mlp,
    critic: Mlp,
    target_actor: Mlp,
    target_critic: Mlp,
    /// A no-autodiff copy of the actor for acting, refreshed after each cycle.
    policy: Mlp,
    /// The actor the anchor penalty holds this one near, once set.
    anchor: Option<Anchor>,
    actor_optimizer: ModuleOptimizer,
    critic_optimizer: ModuleOptimizer,
    /// The second critic, when `config.twin_critics`.
    twin: Option<TwinCritic>,
    /// Optimisation steps taken, which time the actor's delayed updates.
    steps: usize,
    /// Draws the target policy smoothing noise.
    smoothing_rng: ChaCha8Rng,
    pub observation_norm: Normalizer,
    pub goal_norm: Normalizer,
}

impl Agent {
    /// A fresh agent on `device` (a plain backend device, e.g. `Device::flex()`); its initial
    /// weights are drawn from `seed` alone ([`drawn_from_seed`]), so they are reproducible.
    pub fn new(dims: Dims, config: DdpgHerConfig, device: &Device, seed: u64) -> Agent {
        let plain = device.clone();
        let autodiff = device.clone().autodiff();
        let input = dims.observation + dims.goal;
        let (actor, critic, twin_critic) = drawn_from_seed(device, seed, || {
            let actor = Mlp::new(input, &config.hidden, dims.action, &autodiff);
            let critic = Mlp::new(input + dims.action, &config.hidden, 1, &autodiff);
            // Made after the others, so that DDPG's initial weights do not depend on TD3's option.
            let twin_critic = config
                .twin_critics
                .then(|| Mlp::new(input + dims.action, &config.hidden, 1, &autodiff));
            (actor, critic, twin_critic)
        });
        let twin = twin_critic.map(|critic| TwinCritic {
            target: critic.valid(),
            critic,
            optimizer: AdamConfig::new().init(),
        });
        let normalizer =
            |size| Normalizer::new(size, config.norm_eps, config.norm_clip, config.clip_obs);
        Agent {
            target_actor: actor.valid(),
            target_critic: critic.valid(),
            policy: actor.valid(),
            anchor: None,
            actor,
            critic,
            actor_optimizer: AdamConfig::new().init(),
            critic_optimizer: AdamConfig::new().init(),
            twin,
            steps: 0,
            smoothing_rng: ChaCha8Rng::seed_from_u64(seed ^ 0x7D3_5EED),
            observation_norm: normalizer(dims.observation),
            goal_norm: normalizer(dims.goal),
            config,
            dims,
            device: autodiff,
            plain,
        }
    }

    /// Normalised network inputs [o, g] for `n` rows.
    fn inputs(&self, observation: &[f64], goal: &[f64], n: usize, device: &Device) -> Tensor<2> {
        network_inputs(
            &self.observation_norm,
            &self.goal_norm,
            observation,
            goal,
            n,
            device,
        )
    }

    /// Actions for `n` (observation, goal) rows. Exploring adds Gaussian noise of
    /// `noise_eps` and, with probability `random_eps`, takes a uniformly random action.
    pub fn act(
        &self,
        observation: &[f64],
        goal: &[f64],
        n: usize,
        explore: Option<&mut ChaCha8Rng>,
    ) -> Vec<Vec<f64>> {
        let x = self.inputs(observation, goal, n, &self.plain);
        let out = self
            .policy
            .forward(x)
            .tanh()
            .into_data()
            .convert::<f32>()
            .try_to_vec::<f32>()
            .unwrap_or_default();
        let mut actions: Vec<Vec<f64>> = out
            .chunks(self.dims.action)
            .map(|row| row.iter().map(|&a| a as f64).collect())
            .collect();
        if let Some(rng) = explore {
            for action in &mut actions {
                if rng.random::<f64>() < self.config.random_eps {
                    action
                        .iter_mut()
                        .for_each(|a| *a = rng.random_range(-1.0..=1.0));
                } else {
                    for a in action.iter_mut() {
                        *a = (*a + self.config.noise_eps * standard_normal(rng)).clamp(-1.0, 1.0);
                    }
                }
            }
        }
        actions
    }

    /// TD3's target policy smoothing noise for `n` target actions: Gaussian of
    /// `target_noise`, clipped to ±`target_noise_clip`; `None` without smoothing.
    fn smoothing_noise(&mut self, n: usize) -> Option<Tensor<2>> {
        let (sigma, clip) = (self.config.target_noise, self.config.target_noise_clip);
        if sigma <= 0.0 {
            return None;
        }
        let noise: Vec<f32> = (0..n * self.dims.action)
            .map(|_| (sigma * standard_normal(&mut self.smoothing_rng)).clamp(-clip, clip) as f32)
            .collect();
        Some(Tensor::from_data(
            TensorData::new(noise, [n, self.dims.action]),
            &self.plain,
        ))
    }

    /// The critic's regression targets y for `batch`, `[n, 1]` on the plain device, where no
    /// gradient can reach them; `smoothing` is added to the target actions.
    fn targets(&self, batch: &Batch, smoothing: Option<Tensor<2>>) -> Tensor<2> {
        let n = batch.len;
        let x_next = self.inputs(&batch.next_observation, &batch.goal, n, &self.plain);
        let mut next_action = self.target_actor.forward(x_next.clone()).tanh();
        if let Some(noise) = smoothing {
            next_action = (next_action + noise).clamp(-1.0, 1.0);
        }
        let next_input = Tensor::cat(vec![x_next, next_action], 1);
        let mut next_q = self.target_critic.forward(next_input.clone());
        if let Some(twin) = &self.twin {
            next_q = next_q.min_pair(twin.target.forward(next_input));
        }
        let column = |values: &[f32]| -> Tensor<2> {
            Tensor::from_data(TensorData::new(values.to_vec(), [n, 1]), &self.plain)
        };
        let (reward, terminal) = (column(&batch.reward), column(&batch.terminal));
        let lowest = self.config.lowest_target();
        let bootstrapped = reward + next_q * self.config.gamma;
        let failed = terminal.clone() * lowest;
        (bootstrapped * (terminal.neg() + 1.0) + failed).clamp(lowest, 0.0)
    }

    /// The critic's targets for `batch` as numbers (without smoothing noise), for tests and
    /// diagnostics.
    pub fn td_targets(&self, batch: &Batch) -> Vec<f32> {
        self.targets(batch, None)
            .into_data()
            .convert::<f32>()
            .try_to_vec::<f32>()
            .unwrap_or_default()
    }

    /// One optimisation step on `batch` of the critic, and of the actor unless `learners`
    /// holds it.
    pub fn train(&mut self, batch: &Batch, learners: Learners) -> StepStats {
        let (n, da) = (batch.len, self.dims.action);
        let smoothing = self.smoothing_noise(n);
        let target: Tensor<2> =
            Tensor::from_data(self.targets(batch, smoothing).into_data(), &self.device);
        let x = self.inputs(&batch.observation, &batch.goal, n, &self.device);
        let action: Tensor<2> =
            Tensor::from_data(TensorData::new(batch.action.clone(), [n, da]), &self.device);
        let taken = Tensor::cat(vec![x.clone(), action], 1);
        let q = self.critic.forward(taken.clone());
        let critic_loss = (q.clone() - target.clone()).powi_scalar(2).mean();
        if let Some(twin) = self.twin.as_mut() {
            let loss = (twin.critic.forward(taken) - target).powi_scalar(2).mean();
            let grads = GradientsParams::from_grads(loss.backward(), &twin.critic);
            twin.critic = twin
                .optimizer
                .step(self.config.critic_lr, twin.critic.clone(), grads);
        }
        let pi = self.actor.forward(x.clone()).tanh();
        let q_pi = self.critic.forward(Tensor::cat(vec![x, pi.clone()], 1));
        let mut actor_loss =
            q_pi.mean().neg() + pi.clone().powi_scalar(2).mean() * self.config.action_l2;
        if let Some(anchor) = self.anchor.as_ref().filter(|_| self.config.anchor > 0.0) {
            let x = network_inputs(
                &anchor.observation_norm,
                &anchor.goal_norm,
                &batch.observation,
                &batch.goal,
                n,
                &self.plain,
            );
            let held: Tensor<2> =
                Tensor::from_data(anchor.actor.forward(x).tanh().into_data(), &self.device);
            actor_loss = actor_loss + (pi - held).powi_scalar(2).mean() * self.config.anchor;
        }

        let stats = StepStats {
            critic_loss: scalar(&critic_loss),
            actor_loss: scalar(&actor_loss),
            mean_q: scalar(&q.mean()),
        };
        let critic_grads = GradientsParams::from_grads(critic_loss.backward(), &self.critic);
        self.critic =
            self.critic_optimizer
                .step(self.config.critic_lr, self.critic.clone(), critic_grads);
        self.steps += 1;
        let actor_learns = learners == Learners::ActorAndCritic
            && self.steps.is_multiple_of(self.config.policy_delay.max(1));
        if actor_learns {
            let actor_grads = GradientsParams::from_grads(actor_loss.backward(), &self.actor);
            self.actor =
                self.actor_optimizer
                    .step(self.config.actor_lr, self.actor.clone(), actor_grads);
        }
        stats
    }

    /// Polyak-averages the targets towards the networks, and refreshes the acting policy.
    pub fn end_cycle(&mut self) {
        let keep = self.config.polyak as f32;
        let blend = |target: &[f32], online: &[f32]| {
            target
                .iter()
                .zip(online)
                .map(|(t, o)| keep * t + (1.0 - keep) * o)
                .collect()
        };
        self.policy = self.actor.valid();
        let online_actor = params::read(&self.policy);
        let online_critic = params::read(&self.critic.valid());
        self.target_actor =
            params::write(self.target_actor.clone(), &online_actor, blend).expect("same layout");
        self.target_critic =
            params::write(self.target_critic.clone(), &online_critic, blend).expect("same layout");
        if let Some(twin) = self.twin.as_mut() {
            let online = params::read(&twin.critic.valid());
            twin.target = params::write(twin.target.clone(), &online, blend).expect("same layout");
        }
    }

    /// True when no target-network parameter requires a gradient (they live on the plain
    /// device): the guard against burn's target-network pitfalls.
    pub fn targets_track_no_gradients(&self) -> bool {
        struct AnyGrad(bool);
        impl burn::module::ModuleVisitor for AnyGrad {
            fn visit_float<const D: usize>(&mut self, param: &burn::module::Param<Tensor<D>>) {
                self.0 |= param.val().is_require_grad();
            }
        }
        let mut any = AnyGrad(false);
        self.target_actor.visit(&mut any);
        self.target_critic.visit(&mut any);
        if let Some(twin) = &self.twin {
            twin.target.visit(&mut any);
        }
        !any.0
    }

    /// Makes the actor as it is now, with the normalisers as they are now, the anchor that
    /// `DdpgHerConfig::anchor` holds it near.
    pub fn set_anchor_here(&mut self) {
        self.anchor = Some(Anchor {
            actor: self.actor.valid(),
            observation_norm: self.observation_norm.clone(),
            goal_norm: self.goal_norm.clone(),
        });
    }

    /// The anchor, if one is set, as a checkpoint saves it.
    pub fn anchor(&self) -> Option<SavedAnchor> {
        self.anchor.as_ref().map(|anchor| SavedAnchor {
            actor: params::read(&anchor.actor),
            observation_norm: anchor.observation_norm.clone(),
            goal_norm: anchor.goal_norm.clone(),
        })
    }

    /// Sets the anchor to one saved from `anchor`.
    pub fn load_anchor(&mut self, saved: SavedAnchor) -> Result<(), params::ParamMismatch> {
        let replace = |_: &[f32], given: &[f32]| given.to_vec();
        self.anchor = Some(Anchor {
            actor: params::write(self.actor.valid(), &saved.actor, replace)?,
            observation_norm: saved.observation_norm,
            goal_norm: saved.goal_norm,
        });
        Ok(())
    }

    /// Sets the actor's output layer (and its target's) to zero, weights and bias, so that it
    /// acts with zero until it learns otherwise: a residual's start.
    pub fn zero_output(&mut self) {
        let mut networks = self.networks();
        for actor in [0, 2] {
            let layers = &mut networks[actor];
            let last = layers.iter().filter_map(|t| layer_index(&t.name)).max();
            for tensor in layers.iter_mut() {
                if layer_index(&tensor.name) == last {
                    tensor.values.iter_mut().for_each(|v| *v = 0.0);
                }
            }
        }
        self.load_networks(&networks)
            .expect("the agent's own networks fit it");
    }

    /// The actor's parameters: what a shipped policy holds.
    pub fn actor_params(&self) -> Vec<params::NamedTensor> {
        params::read(&self.actor.valid())
    }

    /// The four networks' parameters, for checkpoints: actor, critic, target actor, target critic.
    pub fn networks(&self) -> [Vec<params::NamedTensor>; 4] {
        [
            self.actor_params(),
            params::read(&self.critic.valid()),
            params::read(&self.target_actor),
            params::read(&self.target_critic),
        ]
    }

    /// Loads the four networks saved by `networks` (Adam's moments start afresh).
    pub fn load_networks(
        &mut self,
        saved: &[Vec<params::NamedTensor>; 4],
    ) -> Result<(), params::ParamMismatch> {
        let replace = |_: &[f32], given: &[f32]| given.to_vec();
        self.actor = params::write(self.actor.clone(), &saved[0], replace)?.train();
        self.critic = params::write(self.critic.clone(), &saved[1], replace)?.train();
        self.target_actor = params::write(self.target_actor.clone(), &saved[2], replace)?;
        self.target_critic = params::write(self.target_critic.clone(), &saved[3], replace)?;
        self.policy = self.actor.valid();
        Ok(())
    }

    /// TD3's second critic and its target, as a checkpoint saves them; `None` in DDPG.
    pub fn twin_networks(&self) -> Option<[Vec<params::NamedTensor>; 2]> {
        self.twin.as_ref().map(|twin| {
            [
                params::read(&twin.critic.valid()),
                params::read(&twin.target),
            ]
        })
    }

    /// Loads the second critic and its target saved by `twin_networks`; refuses in DDPG.
    pub fn load_twin_networks(
        &mut self,
        saved: &[Vec<params::NamedTensor>; 2],
    ) -> Result<(), params::ParamMismatch> {
        let replace = |_: &[f32], given: &[f32]| given.to_vec();
        let twin = self.twin.as_mut().ok_or_else(|| {
            params::ParamMismatch::Missing("a second critic in this agent (DDPG has one)".into())
        })?;
        twin.critic = params::write(twin.critic.clone(), &saved[0], replace)?.train();
        twin.target = params::write(twin.target.clone(), &saved[1], replace)?;
        Ok(())
    }

    /// The learner's state beside its networks, with the optimisers' records in the order
    /// of [`LearnerState::parameter_ids`] (actor, critic, then TD3's second critic).
    pub fn learner_state(&self) -> (LearnerState, Vec<OptimizerRecord>) {
        let mut ids = vec![parameter_ids(&self.actor), parameter_ids(&self.critic)];
        let mut records = vec![
            self.actor_optimizer.to_record(),
            self.critic_optimizer.to_record(),
        ];
        if let Some(twin) = &self.twin {
            ids.push(parameter_ids(&twin.critic));
            records.push(twin.optimizer.to_record());
        }
        let state = LearnerState {
            steps: self.steps,
            smoothing_position: self.smoothing_rng.get_word_pos().to_string(),
            parameter_ids: ids,
        };
        (state, records)
    }

    /// Restores what [`Agent::learner_state`] gave, onto an agent whose networks are already
    /// loaded: the networks take the parameter ids the optimisers' moments are keyed by.
    pub fn load_learner_state(
        &mut self,
        state: &LearnerState,
        records: Vec<OptimizerRecord>,
    ) -> Result<(), String> {
        let expected = 2 + self.twin.is_some() as usize;
        if state.parameter_ids.len() != expected || records.len() != expected {
            return Err(format!(
                "it keeps the optimisers of {} networks, this agent has {expected}",
                state.parameter_ids.len()
            ));
        }
        let position: u128 = state
            .smoothing_position
            .parse()
            .map_err(|_| format!("'{}' is no stream position", state.smoothing_position))?;
        let mut restored = state.parameter_ids.iter().zip(records);
        let mut next = || restored.next().expect("counted");
        let (actor_ids, actor_record) = next();
        self.actor = with_parameter_ids(self.actor.clone(), actor_ids)?;
        self.actor_optimizer = AdamConfig::new().init().load_record(actor_record);
        let (critic_ids, critic_record) = next();
        self.critic = with_parameter_ids(self.critic.clone(), critic_ids)?;
        self.critic_optimizer = AdamConfig::new().init().load_record(critic_record);
        if let Some(twin) = self.twin.as_mut() {
            let (twin_ids, twin_record) = next();
            twin.critic = with_parameter_ids(twin.critic.clone(), twin_ids)?;
            twin.optimizer = AdamConfig::new().init().load_record(twin_record);
        }
        self.steps = state.steps;
        self.smoothing_rng.set_word_pos(position);
        self.policy = self.actor.valid();
        Ok(())
    }
}

/// The ids of `module`'s float parameters, in visiting order.
fn parameter_ids<M: Module>(module: &M) -> Vec<u64> {
    struct Ids(Vec<u64>);
    impl ModuleVisitor for Ids {
        fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
            self.0.push(param.id.val());
        }
    }
    let mut ids = Ids(Vec::new());
    module.visit(&mut ids);
    ids.0
}

/// `module` with its float parameters given `ids`, in visiting order, and nothing else changed.
fn with_parameter_ids<M: Module>(module: M, ids: &[u64]) -> Result<M, String> {
    struct Renamer<'a> {
        ids: &'a [u64],
        at: usize,
    }
    impl ModuleMapper for Renamer<'_> {
        fn map_float<const D: usize>(&mut self, mut param: Param<Tensor<D>>) -> Param<Tensor<D>> {
            if let Some(&id) = self.ids.get(self.at) {
                param.id = ParamId::from(id);
            }
            self.at += 1;
            param
        }
    }
    let mut renamer = Renamer { ids, at: 0 };
    let module = module.map(&mut renamer);
    if renamer.at != ids.len() {
        return Err(format!(
            "it keeps moments for {} parameters, the network has {}",
            ids.len(),
            renamer.at
        ));
    }
    Ok(module)
}

/// The layer a parameter named `layers.{i}.…` belongs to.
fn layer_index(name: &str) -> Option<usize> {
    name.strip_prefix("layers.")?
        .split('.')
        .next()?
        .parse()
        .ok()
}

/// A one-element tensor's value (NaN if it has none).
pub(crate) fn scalar(t: &Tensor<1>) -> f64 {
    t.to_data()
        .convert::<f64>()
        .try_to_vec::<f64>()
        .ok()
        .and_then(|v| v.first().copied())
        .unwrap_or(f64::NAN)
}

/// Network inputs for `n` rows: each observation and goal normalised and concatenated, as
/// `[n, observation + goal]`. The agent and a shipped policy build their inputs alike.
pub fn network_inputs(
    observation_norm: &Normalizer,
    goal_norm: &Normalizer,
    observation: &[f64],
    goal: &[f64],
    n: usize,
    device: &Device,
) -> Tensor<2> {
    let (dobs, dgoal) = (observation_norm.size(), goal_norm.size());
    let mut x = Vec::with_capacity(n * (dobs + dgoal));
    for i in 0..n {
        input_row_into(
            (observation_norm, goal_norm),
            &observation[i * dobs..(i + 1) * dobs],
            &goal[i * dgoal..(i + 1) * dgoal],
            &mut x,
        );
    }
    Tensor::from_data(TensorData::new(x, [n, dobs + dgoal]), device)
}

/// One row of network inputs appended to `out`: the leading part of `observation` that the
/// observation normaliser takes, and the goal, each normalised.
pub(crate) fn input_row_into(
    (observation_norm, goal_norm): (&Normalizer, &Normalizer),
    observation: &[f64],
    goal: &[f64],
    out: &mut Vec<f32>,
) {
    observation_norm.normalize_into(&observation[..observation_norm.size()], out);
    goal_norm.normalize_into(&goal[..goal_norm.size()], out);
}
