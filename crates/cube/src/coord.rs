//! Move tables on the two coordinates, and the breadth-first search that turns them into
//! distance tables: the exact table over all positions and the solver's pattern databases.

use crate::cubie::{PERMUTATIONS, Position, TWISTS};
use crate::notation::{Face, Move};

/// Which moves count as one step.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Metric {
    /// Quarter-turn metric, the paper's: `U U' R R' F F'`.
    Quarter,
    /// Half-turn metric: the quarter turns and `U2 R2 F2`, each one step.
    Half,
}

impl Metric {
    /// The generators, with DBL held fixed.
    pub fn moves(self) -> Vec<Move> {
        let quarters = [1, 3];
        let turns: &[u8] = match self {
            Metric::Quarter => &quarters,
            Metric::Half => &[1, 3, 2],
        };
        [Face::U, Face::R, Face::F]
            .into_iter()
            .flat_map(|face| turns.iter().map(move |&q| Move::new(face, q)))
            .collect()
    }
}

/// One coordinate's move table: the state after each generator, `next[state * moves + m]`.
#[derive(Clone, Debug)]
pub struct Axis {
    size: usize,
    moves: usize,
    next: Vec<u16>,
}

impl Axis {
    fn build(size: usize, moves: &[Move], after: impl Fn(usize, Move) -> usize) -> Axis {
        let mut next = Vec::with_capacity(size * moves.len());
        for state in 0..size {
            next.extend(moves.iter().map(|&m| after(state, m) as u16));
        }
        Axis {
            size,
            moves: moves.len(),
            next,
        }
    }

    /// A coordinate with a single state, for searching one coordinate on its own.
    fn point(moves: usize) -> Axis {
        Axis {
            size: 1,
            moves,
            next: vec![0; moves],
        }
    }

    /// The state after generator number `m`.
    #[inline]
    pub fn after(&self, state: usize, m: usize) -> usize {
        self.next[state * self.moves + m] as usize
    }

    fn heap_bytes(&self) -> usize {
        std::mem::size_of_val(self.next.as_slice())
    }
}

/// Where each move sends each coordinate: the permutation and twist move independently.
#[derive(Clone, Debug)]
pub struct CoordMoves {
    moves: Vec<Move>,
    perm: Axis,
    twist: Axis,
}

impl CoordMoves {
    pub fn new(metric: Metric) -> CoordMoves {
        let moves = metric.moves();
        let perm = Axis::build(PERMUTATIONS, &moves, |p, m| {
            Position::from_coords(p, 0).apply(m).perm_coord()
        });
        let twist = Axis::build(TWISTS, &moves, |t, m| {
            Position::from_coords(0, t).apply(m).twist_coord()
        });
        CoordMoves { moves, perm, twist }
    }

    /// Bytes the move tables hold on the heap.
    pub fn heap_bytes(&self) -> usize {
        std::mem::size_of_val(self.moves.as_slice())
            + self.perm.heap_bytes()
            + self.twist.heap_bytes()
    }

    /// The generators, indexed as in the tables.
    pub fn moves(&self) -> &[Move] {
        &self.moves
    }

    /// The permutation coordinate after move number `m`.
    #[inline]
    pub fn perm_after(&self, perm: usize, m: usize) -> usize {
        self.perm.after(perm, m)
    }

    /// The twist coordinate after move number `m`.
    #[inline]
    pub fn twist_after(&self, twist: usize, m: usize) -> usize {
        self.twist.after(twist, m)
    }

    /// The position index (`perm * TWISTS + twist`) after move number `m`.
    #[inline]
    pub fn index_after(&self, index: usize, m: usize) -> usize {
        self.perm_after(index / TWISTS, m) * TWISTS + self.twist_after(index % TWISTS, m)
    }

    /// Distances from solved on the permutation coordinate alone (a lower bound on the whole).
    pub fn perm_distances(&self) -> Vec<u8> {
        breadth_first(&self.perm, &Axis::point(self.moves.len()))
    }

    /// Distances from solved on the twist coordinate alone (a lower bound on the whole).
    pub fn twist_distances(&self) -> Vec<u8> {
        breadth_first(&self.twist, &Axis::point(self.moves.len()))
    }

    /// Exact distances from solved of all 3,674,160 positions, indexed `perm * TWISTS + twist`.
    pub fn position_distances(&self) -> Vec<u8> {
        breadth_first(&self.perm, &self.twist)
    }

    /// A pattern database that sees only where three cubies are and every twist: for each
    /// permutation coordinate, the class of where `cubies` sit (`7 * 7 * 7` classes, some
    /// unused), and distances indexed `class * TWISTS + twist`. The slots of some cubies move
    /// independently of the others, so the abstraction is exact on its own terms and its
    /// distances are admissible bounds.
    pub fn tracked_distances(&self, cubies: [usize; 3]) -> (Vec<u16>, Vec<u8>) {
        let class_of = |p: &Position| cubies.iter().fold(0, |acc, &c| acc * 7 + p.slot_of(c));
        let class_of_perm: Vec<u16> = (0..PERMUTATIONS)
            .map(|p| class_of(&Position::from_coords(p, 0)) as u16)
            .collect();
        let mut representative = vec![0; 343];
        for (p, &class) in class_of_perm.iter().enumerate().rev() {
            representative[class as usize] = p;
        }
        let classes = Axis::build(343, &self.moves, |class, m| {
            class_of(&Position::from_coords(representative[class], 0).apply(m))
        });
        (class_of_perm, breadth_first(&classes, &self.twist))
    }
}

/// Marks states not reached yet.
const UNSEEN: u8 = u8::MAX;

/// Distance from state (0, 0) of every state of the product of two coordinates, indexed
/// `outer * inner.size + inner`. The generators must be closed under inverses. Each level
/// either expands the frontier forwards or, once most states are reached, asks each unseen
/// state whether a neighbour is on the frontier, whichever touches fewer states. States
/// that cannot be reached keep the distance 255.
fn breadth_first(outer: &Axis, inner: &Axis) -> Vec<u8> {
    let (width, moves) = (inner.size, outer.moves);
    let size = outer.size * width;
    let mut distance = vec![UNSEEN; size];
    distance[0] = 0;
    let (mut frontier, mut unseen) = (1, size - 1);
    let mut depth = 0u8;
    while frontier > 0 {
        let forwards = frontier <= unseen;
        let wanted = if forwards { depth } else { UNSEEN };
        let mut reached = 0;
        for a in 0..outer.size {
            let row = a * width;
            if !distance[row..row + width].contains(&wanted) {
                continue;
            }
            let outer_next = &outer.next[a * moves..(a + 1) * moves];
            for b in 0..width {
                if distance[row + b] != wanted {
                    continue;
                }
                let inner_next = &inner.next[b * moves..(b + 1) * moves];
                for (&o, &i) in outer_next.iter().zip(inner_next) {
                    let next = o as usize * width + i as usize;
                    if forwards && distance[next] == UNSEEN {
                        distance[next] = depth + 1;
                        reached += 1;
                    } else if !forwards && distance[next] == depth {
                        distance[row + b] = depth + 1;
                        reached += 1;
                        break;
                    }
                }
            }
        }
        frontier = reached;
        unseen -= reached;
        depth += 1;
    }
    distance
}

/// How many states lie at each distance.
pub fn histogram(distances: &[u8]) -> Vec<u64> {
    let reached = distances.iter().copied().filter(|&d| d != UNSEEN);
    let deepest = reached.max().unwrap_or(0) as usize;
    let mut counts = vec![0u64; deepest + 1];
    for &d in distances.iter().filter(|&&d| d != UNSEEN) {
        counts[d as usize] += 1;
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cubie::POSITIONS;

    #[test]
    fn coordinate_moves_match_cubie_moves() {
        let table = CoordMoves::new(Metric::Half);
        for index in (0..POSITIONS).step_by(9973) {
            let position = Position::from_index(index);
            for (m, &mv) in table.moves().iter().enumerate() {
                assert_eq!(table.index_after(index, m), position.apply(mv).index());
            }
        }
    }

    #[test]
    fn small_searches_reach_every_state() {
        let table = CoordMoves::new(Metric::Quarter);
        assert!(table.perm_distances().iter().all(|&d| d != UNSEEN));
        assert!(table.twist_distances().iter().all(|&d| d != UNSEEN));
    }
}
