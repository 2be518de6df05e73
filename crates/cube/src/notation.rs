//! Faces and moves in standard Singmaster notation: parsing `U U' U2 R ... B'` and printing
//! move sequences, with the quarter-turn metric's cost of each move.

use std::fmt;

/// One of the six faces, in the facelet string's order U R F D L B.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug, PartialOrd, Ord)]
#[repr(u8)]
pub enum Face {
    U,
    R,
    F,
    D,
    L,
    B,
}

impl Face {
    /// All faces in facelet-string order.
    pub const ALL: [Face; 6] = [Face::U, Face::R, Face::F, Face::D, Face::L, Face::B];

    /// The face's letter.
    pub fn letter(self) -> char {
        b"URFDLB"[self as usize] as char
    }

    /// The face named by an upper-case letter.
    pub fn from_letter(letter: char) -> Option<Face> {
        Face::ALL.into_iter().find(|f| f.letter() == letter)
    }

    /// The face on the other side of the cube (U and D, R and L, F and B).
    pub fn opposite(self) -> Face {
        Face::ALL[(self as usize + 3) % 6]
    }

    /// The axis the face lies on: 0 for U/D, 1 for R/L, 2 for F/B.
    pub fn axis(self) -> usize {
        self as usize % 3
    }
}

impl fmt::Display for Face {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.letter())
    }
}

/// A turn of one face by 1, 2 or 3 clockwise quarter turns (`X`, `X2`, `X'`).
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub struct Move {
    pub face: Face,
    /// Clockwise quarter turns, 1 to 3, as seen looking at the face.
    pub quarters: u8,
}

impl Move {
    pub const fn new(face: Face, quarters: u8) -> Move {
        Move { face, quarters }
    }

    /// The twelve quarter turns: `U U' R R' F F' D D' L L' B B'`.
    pub const QUARTER_TURNS: [Move; 12] = {
        let mut all = [Move::new(Face::U, 1); 12];
        let mut i = 0;
        while i < 12 {
            all[i] = Move::new(Face::ALL[i / 2], if i % 2 == 0 { 1 } else { 3 });
            i += 1;
        }
        all
    };

    /// The move that undoes this one.
    pub fn inverse(self) -> Move {
        Move::new(self.face, 4 - self.quarters)
    }

    /// Its length in the quarter-turn metric: 1 for `X` and `X'`, 2 for `X2`.
    pub fn quarter_turn_length(self) -> usize {
        if self.quarters == 2 { 2 } else { 1 }
    }
}

impl fmt::Display for Move {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let suffix = ["", "2", "'"][self.quarters as usize - 1];
        write!(f, "{}{}", self.face, suffix)
    }
}

/// Why a move sequence could not be read. `index` counts moves from 1.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NotationError {
    pub index: usize,
    pub token: String,
    pub reason: String,
}

impl fmt::Display for NotationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "move {} '{}': {}", self.index, self.token, self.reason)
    }
}

impl std::error::Error for NotationError {}

/// Reads a whitespace-separated move sequence such as `R U2 F' D`. A trailing `'` (or the
/// typographic `’`) means counter-clockwise, `2` a half turn; `2'` is accepted as a half turn.
pub fn parse_moves(text: &str) -> Result<Vec<Move>, NotationError> {
    text.split_whitespace()
        .enumerate()
        .map(|(i, token)| {
            parse_move(token).map_err(|reason| NotationError {
                index: i + 1,
                token: token.to_string(),
                reason,
            })
        })
        .collect()
}

fn parse_move(token: &str) -> Result<Move, String> {
    let mut chars = token.chars();
    let letter = chars.next().unwrap_or(' ');
    let face = match Face::from_letter(letter) {
        Some(face) => face,
        None if Face::from_letter(letter.to_ascii_uppercase()).is_some() => {
            return Err(format!(
                "'{letter}' is lower case; faces are the upper-case letters U R F D L B \
                 (wide and slice moves do not exist on a 2x2x2)"
            ));
        }
        None => {
            return Err(format!(
                "'{letter}' is not a face; use U R F D L B, optionally followed by ' or 2"
            ));
        }
    };
    let quarters = match chars.as_str() {
        "" => 1,
        "'" | "’" => 3,
        "2" | "2'" | "2’" => 2,
        rest => {
            return Err(format!(
                "unexpected '{rest}' after {face}; a move is a face letter, optionally followed by ' or 2"
            ));
        }
    };
    Ok(Move::new(face, quarters))
}

/// Prints a move sequence space-separated, `'` for counter-clockwise.
pub fn format_moves(moves: &[Move]) -> String {
    moves
        .iter()
        .map(Move::to_string)
        .collect::<Vec<_>>()
        .join(" ")
}

/// The sequence that undoes `moves`.
pub fn invert_moves(moves: &[Move]) -> Vec<Move> {
    moves.iter().rev().map(|m| m.inverse()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_prints_every_move_form() {
        let moves = parse_moves("U U' U2 R R' R2 F F' F2 D D' D2 L L' L2 B B' B2").unwrap();
        assert_eq!(moves.len(), 18);
        assert_eq!(
            format_moves(&moves),
            "U U' U2 R R' R2 F F' F2 D D' D2 L L' L2 B B' B2"
        );
        assert_eq!(
            parse_moves("R’ U2'").unwrap(),
            parse_moves("R' U2").unwrap()
        );
        assert_eq!(parse_moves("  ").unwrap(), vec![]);
    }

    #[test]
    fn lower_case_is_a_clear_error() {
        let err = parse_moves("R u F").unwrap_err();
        assert_eq!(err.index, 2);
        assert!(err.to_string().contains("lower case"), "{err}");
        let err = parse_moves("R3").unwrap_err();
        assert!(err.to_string().contains("unexpected '3'"), "{err}");
        let err = parse_moves("M").unwrap_err();
        assert!(err.to_string().contains("not a face"), "{err}");
    }

    #[test]
    fn inverse_and_lengths() {
        let moves = parse_moves("R U2 F'").unwrap();
        assert_eq!(format_moves(&invert_moves(&moves)), "F U2 R'");
        let qtm: usize = moves.iter().map(|m| m.quarter_turn_length()).sum();
        assert_eq!(qtm, 4);
        assert_eq!(Face::U.opposite(), Face::D);
        assert_eq!(Face::B.opposite(), Face::F);
        assert_eq!(
            format_moves(&Move::QUARTER_TURNS),
            "U U' R R' F F' D D' L L' B B'"
        );
    }
}
