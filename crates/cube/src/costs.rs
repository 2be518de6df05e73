//! Least-cost solutions of any length, for a solver whose moves have prices that depend on
//! the axis of the move before. A hand that can only turn the top layer one way is such a
//! solver: re-posing the cube for a move on another axis costs more than a turn, and a
//! clockwise quarter turn is three counter-clockwise ones. An optimal (shortest) solution
//! need not be the cheapest: a longer one may re-pose the cube less often.
//!
//! [`CostTable`] holds the least cost to solved from every position and every axis the last
//! move turned about, found by one Dijkstra search backwards from solved over all
//! 3,674,160 × 3 such states (about 22 MB, built in a couple of seconds). A solution is then a
//! greedy descent, as with the distance table.

use crate::coord::{CoordMoves, Metric};
use crate::cubie::{POSITIONS, Position};
use crate::notation::Move;

/// Axes a move turns about: U–D, R–L, F–B (`Face::axis`).
const AXES: usize = 3;

/// Least cost to solved from every position, after a move about each axis.
pub struct CostTable {
    moves: CoordMoves,
    /// `prices[before][m]`: the price of move number `m` after a move about axis `before`
    /// (`AXES` for no move before).
    prices: Vec<Vec<u32>>,
    /// `costs[index * AXES + axis]`: the least cost to solved of the position `index`, the
    /// last move having turned about `axis`.
    costs: Vec<u16>,
}

impl CostTable {
    /// Builds the table for quarter turns of U, R and F priced by `price(axis before, move)`
    /// (`None`: the first move). A price of 0 counts as 1, so that every solution ends.
    ///
    /// Panics if some solution would cost more than `u16::MAX`, which needs prices in the
    /// thousands.
    pub fn build(price: impl Fn(Option<usize>, Move) -> u32) -> CostTable {
        let moves = CoordMoves::new(Metric::Quarter);
        let prices: Vec<Vec<u32>> = (0..=AXES)
            .map(|before| {
                let before = (before < AXES).then_some(before);
                moves
                    .moves()
                    .iter()
                    .map(|&m| price(before, m).max(1))
                    .collect()
            })
            .collect();
        let costs = least_costs(&moves, &prices);
        CostTable {
            moves,
            prices,
            costs,
        }
    }

    /// The least cost of solving `position` when the last move turned about `axis_before`
    /// (`None`: no move before, so the first is priced as a first move).
    pub fn cost(&self, position: &Position, axis_before: Option<usize>) -> u32 {
        self.next_move(position.index(), axis_before)
            .map_or(0, |(cost, _)| cost)
    }

    /// A least costly solution of `position`, of any length; of equally cheap first moves, the
    /// first in move order is taken at each step.
    pub fn cheapest(&self, position: &Position, axis_before: Option<usize>) -> Vec<Move> {
        let (mut index, mut before) = (position.index(), axis_before);
        let mut solution = Vec::new();
        while let Some((_, m)) = self.next_move(index, before) {
            let step = self.moves.moves()[m];
            solution.push(step);
            index = self.moves.index_after(index, m);
            before = Some(step.face.axis());
        }
        solution
    }

    /// (least cost, first move's number) from position `index`; `None` once solved.
    fn next_move(&self, index: usize, before: Option<usize>) -> Option<(u32, usize)> {
        if index == Position::SOLVED.index() {
            return None;
        }
        let row = &self.prices[before.unwrap_or(AXES)];
        self.moves
            .moves()
            .iter()
            .enumerate()
            .map(|(m, step)| {
                let next = self.moves.index_after(index, m);
                let rest = self.costs[next * AXES + step.face.axis()] as u32;
                (row[m] + rest, m)
            })
            .min()
    }

    /// Bytes held by the table and its move tables.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.costs.as_slice()) + self.moves.heap_bytes()
    }
}

/// Dijkstra's search backwards from solved, with a bucket per cost (the prices are small
/// integers): a state (position, axis of the last move) is settled when its bucket comes up.
/// Solved costs 0 whatever the last move; a state reaches its predecessors by the inverse of
/// each move about its axis.
fn least_costs(moves: &CoordMoves, prices: &[Vec<u32>]) -> Vec<u16> {
    let mut costs = vec![u16::MAX; POSITIONS * AXES];
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new()];
    let solved = Position::SOLVED.index();
    for axis in 0..AXES {
        costs[solved * AXES + axis] = 0;
        buckets[0].push((solved * AXES + axis) as u32);
    }
    // The quarter-turn generators come in inverse pairs: X, X'.
    let inverse = |m: usize| m ^ 1;
    let mut cost = 0;
    while cost < buckets.len() {
        for state in std::mem::take(&mut buckets[cost]) {
            let state = state as usize;
            if costs[state] as usize != cost {
                continue;
            }
            let (index, axis) = (state / AXES, state % AXES);
            for (m, step) in moves.moves().iter().enumerate() {
                if step.face.axis() != axis {
                    continue;
                }
                let before_move = moves.index_after(index, inverse(m));
                for (before, row) in prices.iter().take(AXES).enumerate() {
                    let total = cost + row[m] as usize;
                    let target = before_move * AXES + before;
                    assert!(
                        total < u16::MAX as usize,
                        "a solution costs over {}",
                        u16::MAX
                    );
                    if total < costs[target] as usize {
                        costs[target] = total as u16;
                        if buckets.len() <= total {
                            buckets.resize(total + 1, Vec::new());
                        }
                        buckets[total].push(target as u32);
                    }
                }
            }
        }
        cost += 1;
    }
    costs
}
