//! The exact distance table: a breadth-first search of all 3,674,160 positions in the
//! quarter-turn metric. With it an optimal solution is a greedy descent, every optimal
//! solution can be listed or the cheapest picked under a price per move, and positions can be
//! drawn at an exact move distance.

use std::collections::HashMap;

use crate::Solver;
use crate::coord::{CoordMoves, Metric, histogram};
use crate::cubie::Position;
use crate::notation::Move;

/// Distance from solved of every position, one byte each.
pub struct DistanceTable {
    moves: CoordMoves,
    distances: Vec<u8>,
}

impl DistanceTable {
    /// Builds the quarter-turn table, the paper's metric.
    pub fn build() -> DistanceTable {
        DistanceTable::build_in(Metric::Quarter)
    }

    /// Builds the table in either metric.
    pub fn build_in(metric: Metric) -> DistanceTable {
        let moves = CoordMoves::new(metric);
        let distances = moves.position_distances();
        DistanceTable { moves, distances }
    }

    /// The number of moves an optimal solution takes.
    pub fn distance(&self, position: &Position) -> usize {
        self.distances[position.index()] as usize
    }

    /// The largest distance: God's number in this metric.
    pub fn diameter(&self) -> usize {
        self.histogram().len() - 1
    }

    /// How many positions lie at each distance, from 0 to the diameter.
    pub fn histogram(&self) -> Vec<u64> {
        histogram(&self.distances)
    }

    /// The indices of all positions at distance `d`, in increasing order.
    pub fn indices_at(&self, d: usize) -> Vec<usize> {
        (0..self.distances.len())
            .filter(|&i| self.distances[i] as usize == d)
            .collect()
    }

    /// Bytes held by the table and its move tables.
    pub fn memory_bytes(&self) -> usize {
        self.distances.len() + std::mem::size_of_val(&self.moves) + self.moves.heap_bytes()
    }

    /// Every optimal solution, each a sequence of quarter turns of U, R and F, in a fixed order.
    /// `U U` and `U' U'` are listed apart: they do the same, but not for a hand.
    pub fn all_optimal(&self, position: &Position) -> Vec<Vec<Move>> {
        let mut solutions = Vec::new();
        let mut path = Vec::new();
        self.descend_all(position.index(), &mut path, &mut solutions);
        solutions
    }

    /// The optimal solution that costs least when each move has a price, which may depend on
    /// the move before it (`None` for the first). A hand, say, turns U' in one action but U in
    /// three, and needs no re-posing for a second move on the same face. Ties go to the
    /// solution listed first by `all_optimal`.
    pub fn cheapest_optimal(
        &self,
        position: &Position,
        cost: impl Fn(Option<Move>, Move) -> u32,
    ) -> Vec<Move> {
        let mut memo = HashMap::new();
        let (mut index, mut before) = (position.index(), None);
        let mut solution = Vec::with_capacity(self.distances[index] as usize);
        while self.distances[index] > 0 {
            let (_, m) = self.cheapest_from(index, before, &cost, &mut memo);
            solution.push(self.moves.moves()[m]);
            index = self.moves.index_after(index, m);
            before = Some(m);
        }
        solution
    }

    /// (least cost from `index` to solved, the first move's number), `before` being the number
    /// of the move that led here.
    fn cheapest_from(
        &self,
        index: usize,
        before: Option<usize>,
        cost: &dyn Fn(Option<Move>, Move) -> u32,
        memo: &mut HashMap<(usize, Option<usize>), (u32, usize)>,
    ) -> (u32, usize) {
        if self.distances[index] == 0 {
            return (0, usize::MAX);
        }
        if let Some(&known) = memo.get(&(index, before)) {
            return known;
        }
        let moves = self.moves.moves();
        let mut best = (u32::MAX, usize::MAX);
        for (m, next) in self.closer(index) {
            let rest = self.cheapest_from(next, Some(m), cost, memo).0;
            let total = cost(before.map(|b| moves[b]), moves[m]).saturating_add(rest);
            if total < best.0 {
                best = (total, m);
            }
        }
        memo.insert((index, before), best);
        best
    }

    /// The moves (by number) that bring position `index` one step closer to solved, each with
    /// the position it leads to, in move order.
    fn closer(&self, index: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        let here = self.distances[index];
        (0..self.moves.moves().len())
            .map(move |m| (m, self.moves.index_after(index, m)))
            .filter(move |&(_, next)| self.distances[next] + 1 == here)
    }

    fn descend_all(&self, index: usize, path: &mut Vec<Move>, out: &mut Vec<Vec<Move>>) {
        if self.distances[index] == 0 {
            out.push(path.clone());
            return;
        }
        for (m, next) in self.closer(index) {
            path.push(self.moves.moves()[m]);
            self.descend_all(next, path, out);
            path.pop();
        }
    }
}

impl Solver for DistanceTable {
    /// Greedy descent: at each step, the first move that brings the cube one step closer.
    fn solve(&self, position: &Position) -> Vec<Move> {
        let mut index = position.index();
        let mut solution = Vec::with_capacity(self.distances[index] as usize);
        while self.distances[index] > 0 {
            let (m, next) = self
                .closer(index)
                .next()
                .expect("every position but solved has a neighbour one step closer");
            solution.push(self.moves.moves()[m]);
            index = next;
        }
        solution
    }
}
