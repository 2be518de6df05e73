//! # dexcube-cube
//!
//! The 2x2x2 Rubik's cube as a pure puzzle, with no physics: the cube's state as cubies and as
//! a 24-sticker facelet string, the moves and their notation, optimal solvers in the
//! quarter-turn metric, and scrambles drawn at an exact move distance. It is the planner of
//! Li et al., "Learning to Solve a Rubik's Cube with a Dexterous Hand" (IROS 2019), and usable
//! on its own.
//!
//! ```
//! use dexcube_cube::{DistanceTable, Facelets, Position, Solver, format_moves, parse_moves};
//!
//! let scrambled = Facelets::SOLVED.apply_all(&parse_moves("R U F'").unwrap());
//! let table = DistanceTable::build();
//! let solution = table.solve(&Position::of(&scrambled));
//! assert_eq!(solution.len(), 3);
//! println!("{}", format_moves(&solution));
//! assert!(scrambled.apply_all(&solution).is_solved());
//! ```
//!
//! Two solvers give optimal answers of the same length: [`DistanceTable`] (an exact table of
//! all 3,674,160 positions, built in about a tenth of a second) and [`IdaStar`] (the paper's
//! IDA* with a pattern-database heuristic, no big table). For a solver that prices its moves,
//! as a hand does, [`DistanceTable::cheapest_optimal`] takes the cheapest optimal solution and
//! [`CostTable`] the cheapest of any length.

pub mod batch;
pub mod coord;
pub mod costs;
pub mod cubie;
pub mod facelet;
pub mod ida;
pub mod notation;
pub mod scramble;
pub mod table;

pub use costs::CostTable;
pub use cubie::{POSITIONS, Position};
pub use facelet::{FaceletError, Facelets};
pub use ida::IdaStar;
pub use notation::{Face, Move, NotationError, format_moves, invert_moves, parse_moves};
pub use scramble::{Scramble, scrambles_at_distance};
pub use table::DistanceTable;

/// Finds an optimal quarter-turn solution: moves of U, R and F that solve the position.
pub trait Solver: Send + Sync {
    fn solve(&self, position: &Position) -> Vec<Move>;
}

/// Which optimal solver to use.
#[derive(Clone, Copy, PartialEq, Eq, Debug, Default)]
pub enum Method {
    /// Greedy descent in the exact distance table (fastest per solve; 3.5 MB, ~0.1 s to build).
    #[default]
    Table,
    /// The paper's IDA* with a pattern-database heuristic (small tables, slower at depth).
    Ida,
}

impl Method {
    /// Builds the chosen solver.
    pub fn solver(self) -> Box<dyn Solver> {
        match self {
            Method::Table => Box::new(DistanceTable::build()),
            Method::Ida => Box::new(IdaStar::new()),
        }
    }
}
