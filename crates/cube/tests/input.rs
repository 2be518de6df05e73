//! Malformed input never panics, and bad lines in a batch are reported by number.

use dexcube_cube::batch::{BAD_LINE, solve_lines};
use dexcube_cube::{Facelets, IdaStar, Position, Solver, parse_moves};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(5000))]

    /// Any string at all: parsing answers Ok or Err, never panics, and a string it accepts
    /// is a cube that the solver solves.
    #[test]
    fn arbitrary_strings_never_panic(text in "\\PC{0,30}") {
        if let Ok(cube) = Facelets::parse(&text) {
            let solution = IdaStar::new().solve(&Position::of(&cube));
            prop_assert!(cube.apply_all(&solution).is_solved());
        }
        let _ = parse_moves(&text);
    }

    /// Shuffled stickers of a solved cube have the right colour counts, so they reach the
    /// corner, duplicate and twist rules; an accepted one prints back unchanged.
    #[test]
    fn shuffled_stickers_are_judged_without_panicking(seed in any::<u64>()) {
        let mut stickers: Vec<char> = "UUUURRRRFFFFDDDDLLLLBBBB".chars().collect();
        let mut state = seed | 1;
        for i in (1..stickers.len()).rev() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            stickers.swap(i, (state % (i as u64 + 1)) as usize);
        }
        let text: String = stickers.into_iter().collect();
        match Facelets::parse(&text) {
            Ok(cube) => prop_assert_eq!(cube.to_string(), text),
            Err(e) => prop_assert!(!e.to_string().is_empty()),
        }
    }

    /// Strings over the face letters of the right length, some in lower case.
    #[test]
    fn near_miss_strings_never_panic(text in "[URFDLBurfdlb]{24}") {
        let _ = Facelets::parse(&text);
    }
}

#[test]
fn batch_reports_bad_lines_by_number_and_answers_the_rest() {
    let input = "UUUURRRRFFFFDDDDLLLLBBBB\nUFUFRRRRFDFDDBDBLLLLUBUB\nnot a cube\n\nUUUUBBRRRRFFDDDDFFLLLLBB\n";
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let bad = solve_lines(&IdaStar::new(), input.as_bytes(), &mut out, &mut err).unwrap();
    let out = String::from_utf8(out).unwrap();
    let err = String::from_utf8(err).unwrap();
    assert_eq!(bad, 2);
    assert_eq!(
        out.lines().collect::<Vec<_>>(),
        ["", "R'", BAD_LINE, BAD_LINE, "U'"]
    );
    assert!(err.contains("line 3: wrong length"), "{err}");
    assert!(err.contains("line 4: wrong length"), "{err}");
}
