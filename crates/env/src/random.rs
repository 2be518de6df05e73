//! Random draws the environments and the learner share: standard normal numbers and rotations
//! uniform over SO(3).

use std::f64::consts::PI;

use dexcube_sim::rotation::{self, Quat};
use rand::Rng;

/// A standard normal draw (Box–Muller).
pub fn standard_normal(rng: &mut impl Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
}

/// A rotation drawn uniformly from SO(3) (Shoemake's method).
pub fn uniform_rotation(rng: &mut impl Rng) -> Quat {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let (t2, t3) = (2.0 * PI * u2, 2.0 * PI * u3);
    rotation::normalise(&[b * t3.cos(), a * t2.sin(), a * t2.cos(), b * t3.sin()])
}
