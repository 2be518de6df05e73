//! Scrambles at an exact move distance, drawn uniformly from the positions at that distance
//! with a seeded generator: the paper's test set is 100 cubes at each distance 1 to 14.
//!
//! Duplicates: within one distance, positions are drawn without replacement, so a set holds
//! distinct cubes as long as there are enough of them. Distance 1 has 6 positions, 2 has 27
//! and 14 has 276, so a request for more than there are takes every position once, then
//! starts another shuffled pass: each position appears ⌊n/c⌋ or ⌈n/c⌉ times. A smaller
//! count with the same seed is a prefix of a larger one.

use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

use crate::Solver;
use crate::cubie::Position;
use crate::facelet::Facelets;
use crate::notation::{Move, invert_moves};
use crate::table::DistanceTable;

/// A scrambled cube and a shortest sequence that makes it from solved.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Scramble {
    pub facelets: Facelets,
    pub moves: Vec<Move>,
}

/// `count` cubes at exactly `distance` quarter turns from solved, reproducible from `seed`.
/// Each distance draws from its own stream of the seed, so the cubes at one distance do not
/// depend on which other distances are asked for. Empty if no position lies that far.
pub fn scrambles_at_distance(
    table: &DistanceTable,
    distance: usize,
    count: usize,
    seed: u64,
) -> Vec<Scramble> {
    let candidates = table.indices_at(distance);
    if candidates.is_empty() {
        return Vec::new();
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(distance as u64);
    let mut drawn = Vec::with_capacity(count);
    while drawn.len() < count {
        let mut pass = candidates.clone();
        pass.shuffle(&mut rng);
        drawn.extend(pass.into_iter().take(count - drawn.len()));
    }
    drawn
        .into_iter()
        .map(|index| {
            let position = Position::from_index(index);
            Scramble {
                facelets: position.to_facelets(),
                moves: invert_moves(&table.solve(&position)),
            }
        })
        .collect()
}
