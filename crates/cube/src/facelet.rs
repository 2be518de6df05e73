//! The 24-sticker facelet string: its layout, validation with an error per broken rule, face
//! turns on stickers, and the whole-cube orientation a held cube is normalised from.
//!
//! Layout (the project's exchange format): faces in the order U R F D L B, each read left to
//! right, top to bottom on the standard net. U is seen from above with B at the top; R, F, L
//! and B from outside with U at the top; D from below with F at the top. Each letter names the
//! face whose colour the sticker has in the solved cube, so solved is
//! `UUUURRRRFFFFDDDDLLLLBBBB`.

use std::fmt;
use std::str::FromStr;

use crate::notation::{Face, Move};

/// Sticker index of face `f`, square `i` (0 top-left, 1 top-right, 2 bottom-left, 3 bottom-right).
const fn at(face: Face, square: usize) -> usize {
    face as usize * 4 + square
}

use Face::{B, D, F, L, R, U};

/// The eight corner slots, named by their faces. DBL is last: the solver keeps it fixed.
pub const CORNER_NAMES: [&str; 8] = ["URF", "UFL", "ULB", "UBR", "DFR", "DLF", "DRB", "DBL"];

/// Index of the DBL slot, the corner the solver's moves U, R and F never touch.
pub const DBL: usize = 7;

/// For each corner slot, its three stickers in clockwise order seen from outside, starting
/// with the sticker on U or D.
pub const CORNER_FACELETS: [[usize; 3]; 8] = [
    [at(U, 3), at(R, 0), at(F, 1)],
    [at(U, 2), at(F, 0), at(L, 1)],
    [at(U, 0), at(L, 0), at(B, 1)],
    [at(U, 1), at(B, 0), at(R, 1)],
    [at(D, 1), at(F, 3), at(R, 2)],
    [at(D, 0), at(L, 3), at(F, 2)],
    [at(D, 3), at(R, 3), at(B, 2)],
    [at(D, 2), at(B, 3), at(L, 2)],
];

/// The colours of each corner cubie in the solved cube, in the same clockwise order.
pub const CORNER_COLOURS: [[Face; 3]; 8] = [
    [U, R, F],
    [U, F, L],
    [U, L, B],
    [U, B, R],
    [D, F, R],
    [D, L, F],
    [D, R, B],
    [D, B, L],
];

/// A clockwise quarter turn of each face as three 4-cycles of stickers: in each cycle the
/// sticker at one index moves to the next.
const FACE_TURN_CYCLES: [[[usize; 4]; 3]; 6] = [
    // U: the U face, and the top rows F -> L -> B -> R.
    [
        [at(U, 0), at(U, 1), at(U, 3), at(U, 2)],
        [at(F, 0), at(L, 0), at(B, 0), at(R, 0)],
        [at(F, 1), at(L, 1), at(B, 1), at(R, 1)],
    ],
    // R: the R face, and the right column F -> U -> B -> D.
    [
        [at(R, 0), at(R, 1), at(R, 3), at(R, 2)],
        [at(F, 1), at(U, 1), at(B, 2), at(D, 1)],
        [at(F, 3), at(U, 3), at(B, 0), at(D, 3)],
    ],
    // F: the F face, and the ring U -> R -> D -> L next to it.
    [
        [at(F, 0), at(F, 1), at(F, 3), at(F, 2)],
        [at(U, 2), at(R, 0), at(D, 1), at(L, 3)],
        [at(U, 3), at(R, 2), at(D, 0), at(L, 1)],
    ],
    // D: the D face, and the bottom rows F -> R -> B -> L.
    [
        [at(D, 0), at(D, 1), at(D, 3), at(D, 2)],
        [at(F, 2), at(R, 2), at(B, 2), at(L, 2)],
        [at(F, 3), at(R, 3), at(B, 3), at(L, 3)],
    ],
    // L: the L face, and the left column U -> F -> D -> B.
    [
        [at(L, 0), at(L, 1), at(L, 3), at(L, 2)],
        [at(U, 0), at(F, 0), at(D, 0), at(B, 3)],
        [at(U, 2), at(F, 2), at(D, 2), at(B, 1)],
    ],
    // B: the B face, and the ring U -> L -> D -> R next to it.
    [
        [at(B, 0), at(B, 1), at(B, 3), at(B, 2)],
        [at(U, 1), at(L, 0), at(D, 2), at(R, 3)],
        [at(U, 0), at(L, 2), at(D, 3), at(R, 1)],
    ],
];

/// Why a facelet string is not a cube, one variant per rule.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FaceletError {
    WrongLength {
        found: usize,
    },
    LowerCase {
        position: usize,
        letter: char,
    },
    NotAFace {
        position: usize,
        letter: char,
    },
    ColourCount {
        face: Face,
        count: usize,
    },
    RepeatedColour {
        corner: &'static str,
        colours: [Face; 3],
    },
    OppositeColours {
        corner: &'static str,
        colours: [Face; 3],
    },
    MirroredCorner {
        corner: &'static str,
        colours: [Face; 3],
    },
    DuplicateCorner {
        first: &'static str,
        second: &'static str,
        colours: [Face; 3],
    },
    ImpossibleTwist {
        total: u8,
    },
}

fn letters(colours: &[Face; 3]) -> String {
    colours.iter().map(|c| c.letter()).collect()
}

impl fmt::Display for FaceletError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use FaceletError::*;
        match self {
            WrongLength { found } => write!(
                f,
                "wrong length: a facelet string has 24 letters (4 per face, faces in order \
                 U R F D L B), this one has {found}"
            ),
            LowerCase { position, letter } => write!(
                f,
                "lower-case '{letter}' at position {position}: write face letters in upper case \
                 (U R F D L B)"
            ),
            NotAFace { position, letter } => write!(
                f,
                "'{letter}' at position {position} is not a face letter: each sticker is one of \
                 U R F D L B"
            ),
            ColourCount { face, count } => write!(
                f,
                "wrong colour count: {face} appears {count} times, every colour appears exactly 4 times"
            ),
            RepeatedColour { corner, colours } => write!(
                f,
                "a corner that cannot exist: slot {corner} has colours {} with one colour twice",
                letters(colours)
            ),
            OppositeColours { corner, colours } => write!(
                f,
                "opposite colours on one corner: slot {corner} has colours {}, but U/D, R/L and \
                 F/B never share a corner",
                letters(colours)
            ),
            MirroredCorner { corner, colours } => write!(
                f,
                "a corner that cannot exist: slot {corner} reads {} clockwise, the mirror image \
                 of a real corner; check the reading order of its faces",
                letters(colours)
            ),
            DuplicateCorner {
                first,
                second,
                colours,
            } => write!(
                f,
                "a corner that cannot exist: the corner with colours {} is in both slot {first} \
                 and slot {second}",
                letters(colours)
            ),
            ImpossibleTwist { total } => write!(
                f,
                "impossible twist: the corners' twists add up to {total} mod 3 instead of 0, as \
                 if one corner had been twisted in place; re-read the stickers of the corners"
            ),
        }
    }
}

impl std::error::Error for FaceletError {}

/// A valid 24-sticker cube, in any whole-cube orientation. Only `parse` and face turns make one,
/// so every value can be solved.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub struct Facelets([Face; 24]);

impl Facelets {
    /// The solved cube in the standard orientation.
    pub const SOLVED: Facelets = Facelets([
        U, U, U, U, R, R, R, R, F, F, F, F, D, D, D, D, L, L, L, L, B, B, B, B,
    ]);

    /// Reads and validates a facelet string. Surrounding white space is ignored.
    pub fn parse(text: &str) -> Result<Facelets, FaceletError> {
        let text = text.trim();
        let found = text.chars().count();
        if found != 24 {
            return Err(FaceletError::WrongLength { found });
        }
        let mut stickers = [U; 24];
        for (i, letter) in text.chars().enumerate() {
            let position = i + 1;
            stickers[i] = match Face::from_letter(letter) {
                Some(face) => face,
                None if Face::from_letter(letter.to_ascii_uppercase()).is_some() => {
                    return Err(FaceletError::LowerCase { position, letter });
                }
                None => return Err(FaceletError::NotAFace { position, letter }),
            };
        }
        for face in Face::ALL {
            let count = stickers.iter().filter(|&&s| s == face).count();
            if count != 4 {
                return Err(FaceletError::ColourCount { face, count });
            }
        }
        let cube = Facelets(stickers);
        cube.check_corners()?;
        Ok(cube)
    }

    /// The stickers in string order.
    pub fn stickers(&self) -> &[Face; 24] {
        &self.0
    }

    /// True when every face shows a single colour, in whatever orientation the cube is held.
    pub fn is_solved(&self) -> bool {
        self.0
            .chunks(4)
            .all(|face| face.iter().all(|&s| s == face[0]))
    }

    /// The colours in corner slot `slot`, clockwise from its U/D sticker.
    pub fn corner_colours(&self, slot: usize) -> [Face; 3] {
        CORNER_FACELETS[slot].map(|i| self.0[i])
    }

    /// Turns one face by `m.quarters` clockwise quarter turns.
    pub fn apply(&self, m: Move) -> Facelets {
        let mut stickers = self.0;
        for _ in 0..m.quarters {
            let before = stickers;
            for cycle in &FACE_TURN_CYCLES[m.face as usize] {
                for k in 0..4 {
                    stickers[cycle[(k + 1) % 4]] = before[cycle[k]];
                }
            }
        }
        Facelets(stickers)
    }

    /// Applies a sequence of moves in order.
    pub fn apply_all(&self, moves: &[Move]) -> Facelets {
        moves.iter().fold(*self, |cube, &m| cube.apply(m))
    }

    /// The same cube held in each of its 24 whole-cube orientations, itself first.
    pub fn orientations(&self) -> Vec<Facelets> {
        // Opposite face turns together turn the whole cube: x = R L', y = U D'.
        let x = [Move::new(R, 1), Move::new(L, 3)];
        let y = [Move::new(U, 1), Move::new(D, 3)];
        let mut all = vec![*self];
        let mut i = 0;
        while i < all.len() {
            for turn in [&x, &y] {
                let next = all[i].apply_all(turn);
                if !all.contains(&next) {
                    all.push(next);
                }
            }
            i += 1;
        }
        all
    }

    /// The same stickers recoloured so that the cubie in slot DBL shows D, B and L, as if the
    /// whole cube were turned to hold that corner at home. Sticker positions do not change, so
    /// a move sequence that solves the recoloured cube solves this one, in this frame.
    pub fn recoloured_to_fixed_corner(&self) -> Facelets {
        let [d, b, l] = self.corner_colours(DBL);
        let mut recolour = [U; 6];
        for (seen, wanted) in [(d, D), (b, B), (l, L)] {
            recolour[seen as usize] = wanted;
            recolour[seen.opposite() as usize] = wanted.opposite();
        }
        Facelets(self.0.map(|s| recolour[s as usize]))
    }

    /// Identifies the cubie in each slot and its twist (which of its stickers faces U or D),
    /// enforcing every rule but the counts checked in `parse`.
    fn check_corners(&self) -> Result<(), FaceletError> {
        let mut seen_in: [Option<usize>; 8] = [None; 8];
        // The axis the DBL cubie's first sticker colour belongs to plays U/D's part once the
        // cube is recoloured to fixed-corner form; twists are counted against it.
        let reference_axis = self.corner_colours(DBL)[0].axis();
        let mut twist_total = 0;
        for (slot, corner) in CORNER_NAMES.into_iter().enumerate() {
            let colours = self.corner_colours(slot);
            let [a, b, c] = colours;
            if a == b || b == c || a == c {
                return Err(FaceletError::RepeatedColour { corner, colours });
            }
            if a.axis() == b.axis() || b.axis() == c.axis() || a.axis() == c.axis() {
                return Err(FaceletError::OppositeColours { corner, colours });
            }
            let cubie = (0..8)
                .find(|&k| (0..3).any(|r| rotate(colours, r) == CORNER_COLOURS[k]))
                .ok_or(FaceletError::MirroredCorner { corner, colours })?;
            if let Some(first) = seen_in[cubie] {
                return Err(FaceletError::DuplicateCorner {
                    first: CORNER_NAMES[first],
                    second: corner,
                    colours,
                });
            }
            seen_in[cubie] = Some(slot);
            twist_total += colours
                .iter()
                .position(|s| s.axis() == reference_axis)
                .unwrap_or(0);
        }
        match (twist_total % 3) as u8 {
            0 => Ok(()),
            total => Err(FaceletError::ImpossibleTwist { total }),
        }
    }

    /// Builds stickers from a cubie description; used by the cubie module only.
    pub(crate) fn from_stickers(stickers: [Face; 24]) -> Facelets {
        Facelets(stickers)
    }
}

/// `colours` rotated left by `r` places.
fn rotate(colours: [Face; 3], r: usize) -> [Face; 3] {
    [colours[r % 3], colours[(r + 1) % 3], colours[(r + 2) % 3]]
}

impl FromStr for Facelets {
    type Err = FaceletError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Facelets::parse(s)
    }
}

impl fmt::Display for Facelets {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.iter().try_for_each(|s| write!(f, "{}", s.letter()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::notation::parse_moves;

    fn after(moves: &str) -> String {
        Facelets::SOLVED
            .apply_all(&parse_moves(moves).unwrap())
            .to_string()
    }

    #[test]
    fn single_turns_match_the_published_strings() {
        assert_eq!(Facelets::SOLVED.to_string(), "UUUURRRRFFFFDDDDLLLLBBBB");
        assert_eq!(after("R"), "UFUFRRRRFDFDDBDBLLLLUBUB");
        assert_eq!(after("U"), "UUUUBBRRRRFFDDDDFFLLLLBB");
        assert_eq!(after("F"), "UULLURURFFFFRRDDLDLDBBBB");
        // Derived by hand from the same net: D moves the bottom rows F -> R -> B -> L.
        assert_eq!(after("D"), "UUUURRFFFFLLDDDDLLBBBBRR");
        // L moves the left column U -> F -> D -> B; B moves U -> L -> D -> R.
        assert_eq!(after("L"), "BUBURRRRUFUFFDFDLLLLBDBD");
        assert_eq!(after("B"), "RRUURDRDFFFFDDLLULULBBBB");
    }

    #[test]
    fn every_turn_has_order_four_and_opposite_faces_commute() {
        let scrambled = Facelets::parse(&after("R U F' D L2 B")).unwrap();
        for m in Move::QUARTER_TURNS {
            let mut cube = scrambled;
            for _ in 0..4 {
                cube = cube.apply(m);
            }
            assert_eq!(cube, scrambled, "{m}^4");
            assert_ne!(scrambled.apply(m), scrambled);
            let opposite = Move::new(m.face.opposite(), 1);
            assert_eq!(
                scrambled.apply(m).apply(opposite),
                scrambled.apply(opposite).apply(m)
            );
        }
    }

    #[test]
    fn opposite_turns_are_whole_cube_rotations() {
        for moves in ["R L'", "U D'", "F B'"] {
            let rotated = Facelets::parse(&after(moves)).unwrap();
            assert!(
                rotated.is_solved(),
                "{moves} should only turn the whole cube"
            );
            assert_ne!(rotated, Facelets::SOLVED);
            assert_eq!(rotated.recoloured_to_fixed_corner(), Facelets::SOLVED);
        }
    }

    #[test]
    fn a_cube_has_24_orientations_that_all_solve_alike() {
        let scrambled = Facelets::parse(&after("R U F'")).unwrap();
        let all = scrambled.orientations();
        assert_eq!(all.len(), 24);
        assert_eq!(all[0], scrambled);
        assert_eq!(
            Facelets::SOLVED
                .orientations()
                .iter()
                .filter(|c| c.is_solved())
                .count(),
            24
        );
    }

    #[test]
    fn each_rule_has_its_own_error() {
        use FaceletError::*;
        let err = |s: &str| Facelets::parse(s).unwrap_err();
        assert_eq!(err("UUU"), WrongLength { found: 3 });
        assert_eq!(
            err("uUUURRRRFFFFDDDDLLLLBBBB"),
            LowerCase {
                position: 1,
                letter: 'u'
            }
        );
        assert_eq!(
            err("XUUURRRRFFFFDDDDLLLLBBBB"),
            NotAFace {
                position: 1,
                letter: 'X'
            }
        );
        assert_eq!(
            err("UUUURRRRFFFFDDDDLLLLBBBU"),
            ColourCount { face: U, count: 5 }
        );
        // Exchange URF's R sticker with DLF's D sticker: URF then reads U, D, F.
        assert!(matches!(
            err("UUUUDRRRFFFFRDDDLLLLBBBB"),
            OppositeColours { corner: "URF", .. }
        ));
        // Twist the URF corner in place.
        let mut twisted: Vec<char> = "UUUURRRRFFFFDDDDLLLLBBBB".chars().collect();
        let [u, r, f] = CORNER_FACELETS[0];
        (twisted[u], twisted[r], twisted[f]) = ('F', 'U', 'R');
        let twisted: String = twisted.into_iter().collect();
        assert_eq!(err(&twisted), ImpossibleTwist { total: 1 });
        // Swap two stickers of one corner: its mirror image.
        let mut mirrored: Vec<char> = "UUUURRRRFFFFDDDDLLLLBBBB".chars().collect();
        mirrored.swap(r, f);
        let mirrored: String = mirrored.into_iter().collect();
        assert!(matches!(
            err(&mirrored),
            MirroredCorner { corner: "URF", .. }
        ));
        for e in [err("UUU"), err(&twisted), err(&mirrored)] {
            assert!(!e.to_string().is_empty());
        }
    }

    #[test]
    fn repeated_and_duplicate_corners_are_reported() {
        use FaceletError::*;
        // Exchange the U sticker of URF with the R sticker of UBR: URF then reads RRF.
        let mut s: Vec<char> = "UUUURRRRFFFFDDDDLLLLBBBB".chars().collect();
        s.swap(CORNER_FACELETS[0][0], CORNER_FACELETS[3][2]);
        let s: String = s.into_iter().collect();
        assert!(matches!(
            Facelets::parse(&s),
            Err(RepeatedColour { corner: "URF", .. })
        ));
        // Put URF's colours in UFL's slot and DBL's in DRB's: counts stay 4 each.
        let mut s: Vec<char> = "UUUURRRRFFFFDDDDLLLLBBBB".chars().collect();
        for k in 0..3 {
            s[CORNER_FACELETS[1][k]] = CORNER_COLOURS[0][k].letter();
            s[CORNER_FACELETS[6][k]] = CORNER_COLOURS[7][k].letter();
        }
        let s: String = s.into_iter().collect();
        assert!(matches!(
            Facelets::parse(&s),
            Err(DuplicateCorner {
                first: "URF",
                second: "UFL",
                ..
            })
        ));
    }
}
