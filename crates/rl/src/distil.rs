//! Distilling a policy, an ensemble above all, into one actor that acts as it does, by DAgger
//! (Ross, Gordon and Bagnell 2011, "A Reduction of Imitation Learning and Structured Prediction
//! to No-Regret Online Learning"): the teacher labels, with its deterministic action, every
//! state in episodes run first by itself and then by the student, and the student is fitted to
//! all the labels gathered so far after each round. Labelling the student's own states is what
//! keeps its small errors from carrying it where the teacher's episodes never went.
//!
//! The student starts as the teacher's first member, with its weights and its normalisers,
//! which stay fixed: it reads its inputs exactly as that member did, so it can be fine-tuned
//! afterwards like any single policy. This module owns the labels ([`Demonstrations`]) and the
//! fit ([`fit`]); whoever runs the episodes (the `dexcube distil` command) decides who acts.

use burn::optim::{AdamConfig, GradientsParams};
use burn::prelude::*;
use burn::tensor::TensorData;
use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::agent::{input_row_into, scalar};
use crate::networks::Mlp;
use crate::params::{self, ParamMismatch};
use crate::policy::Policy;

/// How the student is fitted to the labels after each round.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct DistilConfig {
    /// Passes over all the labels gathered so far, after each round.
    pub epochs: usize,
    /// Rows per Adam step: the DDPG+HER baselines' batch size.
    pub batch_size: usize,
    /// Adam's learning rate: the baselines' actor learning rate.
    pub lr: f64,
}

impl Default for DistilConfig {
    fn default() -> DistilConfig {
        DistilConfig {
            epochs: 10,
            batch_size: 256,
            lr: 1e-3,
        }
    }
}

/// States and the teacher's actions there: the student's network inputs (normalised by the
/// student's fixed normalisers) and the teacher's deterministic actions, row by row.
#[derive(Clone, Debug, Default)]
pub struct Demonstrations {
    inputs: Vec<f32>,
    actions: Vec<f32>,
    rows: usize,
}

impl Demonstrations {
    /// Labels one state: records the student's inputs there and the teacher's action, and
    /// returns that action.
    pub fn label(
        &mut self,
        teacher: &Policy,
        student: &Policy,
        observation: &[f64],
        goal: &[f64],
    ) -> Vec<f64> {
        let card = &student.card;
        input_row_into(
            (&card.observation_norm, &card.goal_norm),
            observation,
            goal,
            &mut self.inputs,
        );
        let action = teacher.act(observation, goal);
        self.actions.extend(action.iter().map(|&a| a as f32));
        self.rows += 1;
        action
    }

    /// Appends another set of labels (one episode's, gathered on another thread).
    pub fn extend(&mut self, other: Demonstrations) {
        self.inputs.extend(other.inputs);
        self.actions.extend(other.actions);
        self.rows += other.rows;
    }

    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The mean squared difference between `policy`'s actions and the teacher's over every
    /// row, each action component counted once; `policy` must read its inputs as the student
    /// does (the student, or a fit of it).
    pub fn mean_squared_error(&self, policy: &Policy) -> f64 {
        if self.rows == 0 {
            return 0.0;
        }
        let width = self.inputs.len() / self.rows;
        let x = Tensor::from_data(
            TensorData::new(self.inputs.clone(), [self.rows, width]),
            &policy.device,
        );
        let action = self.actions.len() / self.rows;
        let y = Tensor::from_data(
            TensorData::new(self.actions.clone(), [self.rows, action]),
            &policy.device,
        );
        let error = (policy.actor.forward(x).tanh() - y).powi_scalar(2).mean();
        scalar(&error)
    }
}

/// The student fitted by Adam to every row of `demonstrations` (mean squared error between its
/// tanh actions and the teacher's), starting from its present weights, rows shuffled by `seed`.
pub fn fit(
    student: &Policy,
    demonstrations: &Demonstrations,
    config: DistilConfig,
    seed: u64,
) -> Result<Policy, ParamMismatch> {
    let device = student.device.clone().autodiff();
    let dims = student.card.dims;
    let fresh = Mlp::new(
        dims.observation + dims.goal,
        &student.card.config.hidden,
        dims.action,
        &device,
    );
    let mut actor = params::write(fresh, &params::read(&student.actor), |_, given| {
        given.to_vec()
    })?
    .train();
    let mut optimizer = AdamConfig::new().init();
    let rows = demonstrations.rows;
    let width = dims.observation + dims.goal;
    let mut order: Vec<usize> = (0..rows).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for _ in 0..config.epochs {
        order.shuffle(&mut rng);
        for batch in order.chunks(config.batch_size.max(1)) {
            let gather = |source: &[f32], size: usize| {
                let mut out = Vec::with_capacity(batch.len() * size);
                for &row in batch {
                    out.extend_from_slice(&source[row * size..(row + 1) * size]);
                }
                Tensor::<2>::from_data(TensorData::new(out, [batch.len(), size]), &device)
            };
            let x = gather(&demonstrations.inputs, width);
            let y = gather(&demonstrations.actions, dims.action);
            let loss = (actor.forward(x).tanh() - y).powi_scalar(2).mean();
            let grads = GradientsParams::from_grads(loss.backward(), &actor);
            actor = optimizer.step(config.lr, actor, grads);
        }
    }
    Ok(student.with_actor(actor.valid()))
}
