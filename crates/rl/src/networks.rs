//! The actor and critic: multilayer perceptrons with ReLU between layers. The actor's output
//! goes through tanh; the critic's is a single unbounded value. Code is backend-agnostic:
//! the device a network is made on (burn's `flex` CPU backend here, CUDA where enabled)
//! decides where it runs.

use burn::nn::{Linear, LinearConfig, Relu};
use burn::prelude::*;
use std::sync::{Mutex, PoisonError};

/// burn's device draws every initial weight from one generator per process, so a seed and the
/// draws it is meant for must not be split by another thread's seeding.
static SEEDED_DRAWS: Mutex<()> = Mutex::new(());

/// Seeds `device`'s generator with `seed` and runs `draw` (which makes networks on it) before
/// any other seeded draw in the process, so the networks depend on `seed` alone, whichever
/// other agents or tests are being made at the same time.
pub fn drawn_from_seed<T>(device: &Device, seed: u64, draw: impl FnOnce() -> T) -> T {
    let _only_draw = SEEDED_DRAWS.lock().unwrap_or_else(PoisonError::into_inner);
    device.seed(seed);
    draw()
}

#[derive(Module, Debug)]
pub struct Mlp {
    layers: Vec<Linear>,
    activation: Relu,
}

impl Mlp {
    /// `input` -> each of `hidden` -> `output`.
    pub fn new(input: usize, hidden: &[usize], output: usize, device: &Device) -> Mlp {
        let sizes: Vec<usize> = std::iter::once(input)
            .chain(hidden.iter().copied())
            .chain([output])
            .collect();
        let layers = sizes
            .windows(2)
            .map(|w| LinearConfig::new(w[0], w[1]).init(device))
            .collect();
        Mlp {
            layers,
            activation: Relu::new(),
        }
    }

    pub fn forward(&self, mut x: Tensor<2>) -> Tensor<2> {
        let last = self.layers.len() - 1;
        for (i, layer) in self.layers.iter().enumerate() {
            x = layer.forward(x);
            if i < last {
                x = self.activation.forward(x);
            }
        }
        x
    }
}
