//! `dexcube solve` and `dexcube scramble`: the planner on the command line.

use std::fs::File;
use std::io::{self, BufReader, Write};
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use dexcube_cube::batch::solve_lines;
use dexcube_cube::{
    DistanceTable, Facelets, Method, Position, format_moves, parse_moves, scrambles_at_distance,
};

#[derive(Clone, Copy, ValueEnum)]
pub enum MethodArg {
    /// Greedy descent in the exact distance table.
    Table,
    /// IDA* with a pattern-database heuristic, the paper's planner.
    Ida,
}

impl From<MethodArg> for Method {
    fn from(arg: MethodArg) -> Method {
        match arg {
            MethodArg::Table => Method::Table,
            MethodArg::Ida => Method::Ida,
        }
    }
}

/// Prints an optimal quarter-turn solution (moves of U, R, F; ' is counter-clockwise). A
/// solved cube prints an empty line.
#[derive(Args)]
pub struct SolveArgs {
    /// The cube as 24 facelet letters, faces in order U R F D L B (solved:
    /// UUUURRRRFFFFDDDDLLLLBBBB). Any whole-cube orientation is accepted.
    #[arg(required_unless_present_any = ["scramble", "batch"], conflicts_with_all = ["scramble", "batch"])]
    facelets: Option<String>,
    /// Solve the cube made by this move sequence from solved, e.g. "R U F' D2".
    #[arg(long, conflicts_with = "batch")]
    scramble: Option<String>,
    /// Solve one facelet string per line of FILE ('-' for standard input); one answer per
    /// line, in order, and ERROR for a bad line (reported on stderr with its number).
    #[arg(long, value_name = "FILE")]
    batch: Option<String>,
    /// Which optimal solver to use.
    #[arg(long, value_enum, default_value = "table")]
    method: MethodArg,
    /// Print every optimal solution, one per line.
    #[arg(long, conflicts_with = "batch")]
    all: bool,
}

pub fn solve(args: SolveArgs) -> anyhow::Result<ExitCode> {
    if let Some(path) = &args.batch {
        return solve_batch(path, args.method.into());
    }
    let cube = match (&args.facelets, &args.scramble) {
        (Some(text), _) => Facelets::parse(text).context("not a valid cube")?,
        (None, Some(moves)) => {
            Facelets::SOLVED.apply_all(&parse_moves(moves).context("cannot read the scramble")?)
        }
        (None, None) => bail!("give a facelet string, --scramble or --batch"),
    };
    let position = Position::of(&cube);
    let mut out = io::stdout().lock();
    if args.all {
        for solution in DistanceTable::build().all_optimal(&position) {
            writeln!(out, "{}", format_moves(&solution))?;
        }
    } else {
        let solution = Method::from(args.method).solver().solve(&position);
        writeln!(out, "{}", format_moves(&solution))?;
    }
    Ok(ExitCode::SUCCESS)
}

fn solve_batch(path: &str, method: Method) -> anyhow::Result<ExitCode> {
    let solver = method.solver();
    let (stdout, stderr) = (io::stdout().lock(), io::stderr().lock());
    let bad = if path == "-" {
        solve_lines(solver.as_ref(), io::stdin().lock(), stdout, stderr)?
    } else {
        let file = File::open(path)
            .with_context(|| format!("cannot open batch file {path}: check the path"))?;
        solve_lines(solver.as_ref(), BufReader::new(file), stdout, stderr)?
    };
    if bad > 0 {
        eprintln!("{bad} line(s) were not valid cubes");
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}

/// Prints facelet strings of cubes drawn uniformly at an exact move distance.
#[derive(Args)]
pub struct ScrambleArgs {
    /// Quarter turns from solved, 0 to 14.
    #[arg(long, short)]
    distance: usize,
    /// How many cubes. Positions are distinct while there are enough of them at this distance.
    #[arg(long, short = 'n', default_value_t = 1)]
    count: usize,
    /// Seed of the draw; the same seed gives the same cubes.
    #[arg(long, short, default_value_t = 0)]
    seed: u64,
    /// Also print, after a tab, a shortest move sequence that makes each cube from solved.
    #[arg(long)]
    show_moves: bool,
}

pub fn scramble(args: ScrambleArgs) -> anyhow::Result<ExitCode> {
    if args.distance > 14 {
        bail!(
            "no 2x2x2 position lies {} quarter turns from solved; the largest distance is 14",
            args.distance
        );
    }
    let table = DistanceTable::build();
    let mut out = io::stdout().lock();
    for scramble in scrambles_at_distance(&table, args.distance, args.count, args.seed) {
        if args.show_moves {
            writeln!(
                out,
                "{}\t{}",
                scramble.facelets,
                format_moves(&scramble.moves)
            )?;
        } else {
            writeln!(out, "{}", scramble.facelets)?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
