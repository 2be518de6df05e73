//! The cubie representation: which corner cubie sits in each slot and how it is twisted,
//! with face turns as permutations, conversions to and from facelets, and the two coordinates
//! (corner permutation and twist) that index the solver's tables.
//!
//! A `Position` is a cubie cube held with its DBL cubie at home and untwisted. Every cube is
//! one of these up to a whole-cube turn, and the moves U, R and F (the paper's quarter-turn
//! set) never disturb DBL, so the 3,674,160 positions (7! permutations times 3^6 twists) are
//! the whole puzzle.

use std::sync::OnceLock;

use crate::facelet::{CORNER_COLOURS, CORNER_FACELETS, Facelets};
use crate::notation::{Face, Move};

/// Corner cubies by slot: `perm[i]` is the cubie in slot `i`, `twist[i]` how many clockwise
/// thirds it is turned from having its U/D colour on the slot's U/D face.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub struct CubieCube {
    perm: [u8; 8],
    twist: [u8; 8],
}

impl CubieCube {
    pub const SOLVED: CubieCube = CubieCube {
        perm: [0, 1, 2, 3, 4, 5, 6, 7],
        twist: [0; 8],
    };

    /// This cube followed by `other` (applied as a move): the composition of the two.
    pub fn then(&self, other: &CubieCube) -> CubieCube {
        let mut out = CubieCube::SOLVED;
        for i in 0..8 {
            let from = other.perm[i] as usize;
            out.perm[i] = self.perm[from];
            out.twist[i] = (self.twist[from] + other.twist[i]) % 3;
        }
        out
    }

    /// The cube after one face turn.
    pub fn apply(&self, m: Move) -> CubieCube {
        self.then(&face_turns()[m.face as usize][m.quarters as usize - 1])
    }

    /// The stickers of this cube in the standard orientation.
    pub fn to_facelets(&self) -> Facelets {
        let mut stickers = [Face::U; 24];
        for slot in 0..8 {
            let colours = CORNER_COLOURS[self.perm[slot] as usize];
            for (k, colour) in colours.into_iter().enumerate() {
                stickers[CORNER_FACELETS[slot][(k + self.twist[slot] as usize) % 3]] = colour;
            }
        }
        Facelets::from_stickers(stickers)
    }

    /// Reads the cubies of a valid cube whose colours are in the standard scheme.
    fn from_standard_facelets(cube: &Facelets) -> CubieCube {
        let mut out = CubieCube::SOLVED;
        for slot in 0..8 {
            let colours = cube.corner_colours(slot);
            let twist = colours.iter().position(|c| c.axis() == 0).unwrap_or(0);
            let second = colours[(twist + 1) % 3];
            let first = colours[twist];
            out.perm[slot] = CORNER_COLOURS
                .iter()
                .position(|c| c[0] == first && c[1] == second)
                .expect("validated facelets hold only real corners")
                as u8;
            out.twist[slot] = twist as u8;
        }
        out
    }
}

/// The 3 turns (quarter, half, counter-quarter) of each face as cubie cubes, derived from the
/// sticker cycles so that the two representations cannot disagree.
fn face_turns() -> &'static [[CubieCube; 3]; 6] {
    static TURNS: OnceLock<[[CubieCube; 3]; 6]> = OnceLock::new();
    TURNS.get_or_init(|| {
        Face::ALL.map(|face| {
            [1, 2, 3].map(|q| {
                CubieCube::from_standard_facelets(&Facelets::SOLVED.apply(Move::new(face, q)))
            })
        })
    })
}

/// Number of corner permutations with DBL fixed (7!).
pub const PERMUTATIONS: usize = 5040;
/// Number of corner twists with DBL untwisted (3^6; the seventh twist follows).
pub const TWISTS: usize = 729;
/// Number of positions: the size of the 2x2x2 puzzle.
pub const POSITIONS: usize = PERMUTATIONS * TWISTS;

/// A cube held with its DBL cubie at home, untwisted: the solver's view of any cube.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub struct Position(CubieCube);

impl Position {
    pub const SOLVED: Position = Position(CubieCube::SOLVED);

    /// The position of any valid cube, in whatever orientation it is held. Moves that solve
    /// the position solve the cube as given, in its own frame.
    pub fn of(cube: &Facelets) -> Position {
        Position(CubieCube::from_standard_facelets(
            &cube.recoloured_to_fixed_corner(),
        ))
    }

    /// The position with the given coordinates. Panics if they are out of range.
    pub fn from_coords(perm: usize, twist: usize) -> Position {
        assert!(
            perm < PERMUTATIONS && twist < TWISTS,
            "coordinate out of range"
        );
        let mut cube = CubieCube::SOLVED;
        // Lehmer code, most significant digit first.
        let mut remaining: Vec<u8> = (0..7).collect();
        let mut rank = perm;
        for i in 0..7 {
            let radix = factorial(6 - i);
            cube.perm[i] = remaining.remove(rank / radix);
            rank %= radix;
        }
        let mut digits = twist;
        let mut total = 0;
        for i in (0..6).rev() {
            cube.twist[i] = (digits % 3) as u8;
            total += cube.twist[i];
            digits /= 3;
        }
        cube.twist[6] = (3 - total % 3) % 3;
        Position(cube)
    }

    /// The slot that cubie `cubie` (numbered as the slots it belongs in) occupies.
    pub fn slot_of(&self, cubie: usize) -> usize {
        self.0
            .perm
            .iter()
            .position(|&c| c as usize == cubie)
            .unwrap_or(cubie)
    }

    /// The position with a table index (`perm * TWISTS + twist`).
    pub fn from_index(index: usize) -> Position {
        Position::from_coords(index / TWISTS, index % TWISTS)
    }

    /// Rank of the permutation of the seven free cubies, 0 for solved.
    pub fn perm_coord(&self) -> usize {
        let p = &self.0.perm;
        (0..7).fold(0, |rank, i| {
            let smaller_after = (i + 1..7).filter(|&j| p[j] < p[i]).count();
            rank + smaller_after * factorial(6 - i)
        })
    }

    /// The twists of slots URF to DRB as a base-3 number, 0 for solved.
    pub fn twist_coord(&self) -> usize {
        self.0.twist[..6]
            .iter()
            .fold(0, |acc, &t| acc * 3 + t as usize)
    }

    /// The index of this position in a table over all positions.
    pub fn index(&self) -> usize {
        self.perm_coord() * TWISTS + self.twist_coord()
    }

    /// The position after a move of U, R or F. Moves of D, L and B turn the held corner;
    /// apply those to `Facelets` and take the new `Position::of` instead.
    pub fn apply(&self, m: Move) -> Position {
        debug_assert!(matches!(m.face, Face::U | Face::R | Face::F));
        Position(self.0.apply(m))
    }

    /// The cube's stickers, held with DBL at home.
    pub fn to_facelets(&self) -> Facelets {
        self.0.to_facelets()
    }

    pub fn is_solved(&self) -> bool {
        self.0 == CubieCube::SOLVED
    }
}

const fn factorial(n: usize) -> usize {
    if n == 0 { 1 } else { n * factorial(n - 1) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facelet::DBL;
    use crate::notation::parse_moves;

    #[test]
    fn cubie_and_facelet_turns_agree() {
        let moves = parse_moves("R U F' D L2 B U' R2 F D' L B2").unwrap();
        let mut cubies = CubieCube::SOLVED;
        let mut stickers = Facelets::SOLVED;
        for m in moves {
            cubies = cubies.apply(m);
            stickers = stickers.apply(m);
            assert_eq!(cubies.to_facelets(), stickers, "after {m}");
            assert_eq!(CubieCube::from_standard_facelets(&stickers), cubies);
        }
    }

    #[test]
    fn coordinates_round_trip_over_the_whole_range() {
        for perm in (0..PERMUTATIONS).step_by(7) {
            for twist in (0..TWISTS).step_by(11) {
                let p = Position::from_coords(perm, twist);
                assert_eq!((p.perm_coord(), p.twist_coord()), (perm, twist));
                assert_eq!(Position::of(&p.to_facelets()), p);
            }
        }
        assert_eq!(Position::SOLVED.index(), 0);
        assert_eq!(Position::from_index(POSITIONS - 1).index(), POSITIONS - 1);
    }

    #[test]
    fn turns_of_u_r_f_leave_dbl_home() {
        for m in Move::QUARTER_TURNS
            .into_iter()
            .filter(|m| matches!(m.face, Face::U | Face::R | Face::F))
        {
            let cube = CubieCube::SOLVED.apply(m);
            assert_eq!((cube.perm[DBL], cube.twist[DBL]), (DBL as u8, 0), "{m}");
        }
    }
}
