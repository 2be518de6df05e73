//! Solving many cubes from a stream, one facelet string per line, one answer per line in the
//! same order, so the output lines up with the input for other tools.

use std::io::{self, BufRead, Write};

use crate::Solver;
use crate::cubie::Position;
use crate::facelet::Facelets;
use crate::notation::format_moves;

/// What a bad input line gets on the answer stream, so answers stay aligned with lines. No
/// move sequence reads like this; a solved cube's answer is an empty line.
pub const BAD_LINE: &str = "ERROR";

/// Solves each line of `input`, writing answers to `output` and a message naming the line
/// number for each bad line to `diagnostics`. Returns how many lines were bad.
pub fn solve_lines(
    solver: &dyn Solver,
    input: impl BufRead,
    mut output: impl Write,
    mut diagnostics: impl Write,
) -> io::Result<usize> {
    let mut bad = 0;
    for (number, line) in input.lines().enumerate() {
        match Facelets::parse(&line?) {
            Ok(cube) => writeln!(
                output,
                "{}",
                format_moves(&solver.solve(&Position::of(&cube)))
            )?,
            Err(e) => {
                bad += 1;
                writeln!(output, "{BAD_LINE}")?;
                writeln!(diagnostics, "line {}: {e}", number + 1)?;
            }
        }
    }
    output.flush()?;
    Ok(bad)
}
