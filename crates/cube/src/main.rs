//! `cargo run -p dexcube-cube -- [FACELETS...]`: the optimal solver on its own, with no
//! physics. Solves each facelet string given as an argument, or else each line of standard
//! input, printing one quarter-turn solution per line (ERROR for a bad one, explained on
//! stderr, with exit status 1).

use std::io::{self, Cursor};
use std::process::ExitCode;

use dexcube_cube::DistanceTable;
use dexcube_cube::batch::solve_lines;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let table = DistanceTable::build();
    let (out, err) = (io::stdout().lock(), io::stderr().lock());
    let result = if args.is_empty() {
        solve_lines(&table, io::stdin().lock(), out, err)
    } else {
        solve_lines(&table, Cursor::new(args.join("\n")), out, err)
    };
    match result {
        Ok(0) => ExitCode::SUCCESS,
        Ok(_) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
