//! The actor and critic: multilayer perceptrons with ReLU between layers. The actor's output
//! goes through tanh; the critic's is a single unbounded value. Code is backend-agnostic:
//! the device a network is made on (burn's `flex` CPU backend here, CUDA where enabled)
//! decides where it runs.

use burn::nn::{Linear, LinearConfig, Relu};
use burn::prelude::*;

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
