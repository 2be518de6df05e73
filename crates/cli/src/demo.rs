//! `dexcube demo`: the project's main job. Until the hand lands, it scrambles a cube at a
//! move distance, plans the optimal solution and plays it move by move on the net.

use std::io::{self, IsTerminal, Write};
use std::process::ExitCode;

use clap::Args;
use dexcube_cube::{DistanceTable, Position, Solver, format_moves, scrambles_at_distance};

use crate::net;

/// Scrambles a cube, plans an optimal solution and shows it being carried out.
#[derive(Args)]
pub struct DemoArgs {
    /// Move distance of the scramble, 1 to 14 quarter turns.
    #[arg(long, short, default_value_t = 14, value_parser = clap::value_parser!(u8).range(1..=14))]
    distance: u8,
    /// Seed of the scramble.
    #[arg(long, short, default_value_t = 0)]
    seed: u64,
}

pub fn run(args: DemoArgs) -> anyhow::Result<ExitCode> {
    let colour = io::stdout().is_terminal();
    let table = DistanceTable::build();
    let scramble = scrambles_at_distance(&table, args.distance as usize, 1, args.seed)
        .pop()
        .expect("every distance from 1 to 14 has positions");
    let plan = table.solve(&Position::of(&scramble.facelets));
    let mut out = io::stdout().lock();
    writeln!(
        out,
        "Scrambled cube at move distance {} (seed {}): {}",
        args.distance, args.seed, scramble.facelets
    )?;
    write!(out, "{}", net::draw(&scramble.facelets, colour))?;
    writeln!(
        out,
        "Optimal plan, {} quarter turns: {}\n",
        plan.len(),
        format_moves(&plan)
    )?;
    let mut cube = scramble.facelets;
    for (step, m) in plan.iter().enumerate() {
        cube = cube.apply(*m);
        writeln!(out, "{:>2}. {:<2}  {}", step + 1, m.to_string(), cube)?;
    }
    write!(out, "\n{}", net::draw(&cube, colour))?;
    writeln!(
        out,
        "{}",
        if cube.is_solved() {
            "Solved."
        } else {
            "Not solved."
        }
    )?;
    Ok(if cube.is_solved() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}
