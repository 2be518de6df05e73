//! Draws a cube's facelets as the standard unfolded net, in colour on a terminal.

use dexcube_cube::{Face, Facelets};

/// Rows of the net as (face, first square) pairs, two squares each; `None` is blank.
const NET_ROWS: [[Option<(Face, usize)>; 4]; 6] = {
    use Face::*;
    [
        [None, Some((U, 0)), None, None],
        [None, Some((U, 2)), None, None],
        [Some((L, 0)), Some((F, 0)), Some((R, 0)), Some((B, 0))],
        [Some((L, 2)), Some((F, 2)), Some((R, 2)), Some((B, 2))],
        [None, Some((D, 0)), None, None],
        [None, Some((D, 2)), None, None],
    ]
};

/// Standard colour scheme: U white, R red, F green, D yellow, L orange, B blue (ANSI 256).
fn ansi_colour(face: Face) -> u8 {
    match face {
        Face::U => 15,
        Face::R => 160,
        Face::F => 34,
        Face::D => 226,
        Face::L => 208,
        Face::B => 27,
    }
}

/// The net, one line per row of stickers; each sticker is its letter, on its colour if
/// `colour` is set.
pub fn draw(cube: &Facelets, colour: bool) -> String {
    let stickers = cube.stickers();
    let mut out = String::new();
    for row in NET_ROWS {
        let mut line = String::new();
        for cell in row {
            match cell {
                None => line.push_str("      "),
                Some((face, first)) => {
                    for square in [first, first + 1] {
                        let s = stickers[face as usize * 4 + square];
                        if colour {
                            line += &format!("\x1b[30;48;5;{}m {} \x1b[0m", ansi_colour(s), s);
                        } else {
                            line += &format!(" {s} ");
                        }
                    }
                }
            }
        }
        out += line.trim_end();
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solved_net_shows_each_face_in_its_place() {
        let net = draw(&Facelets::SOLVED, false);
        let lines: Vec<&str> = net.lines().collect();
        assert_eq!(lines[0].trim(), "U  U");
        assert_eq!(lines[2], " L  L  F  F  R  R  B  B");
        assert_eq!(lines[5].trim(), "D  D");
    }
}
