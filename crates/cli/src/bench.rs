//! `dexcube bench`: performance figures printed by the tool itself, each beside a baseline
//! measured in the same run, because these machines are noisy.

use std::hint::black_box;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use clap::{Args, Subcommand};
use dexcube_cube::{DistanceTable, IdaStar, Position, Solver, scrambles_at_distance};
use serde::Serialize;

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Table build time, optimal solve time per move distance (table and IDA*), table memory.
    Solver(SolverArgs),
    /// Control steps per second of each scene, beside a raw mj_step loop, on 1 and 2 threads.
    Sim(crate::bench_sim::SimArgs),
    /// Environment steps per second on 1, 2 and all threads, beside the bare simulator.
    Env(crate::bench_env::EnvArgs),
    /// The learner: time per optimisation batch and per inference, and the balance of a
    /// short training run.
    Rl(crate::bench_rl::RlArgs),
}

#[derive(Args)]
pub struct SolverArgs {
    /// Cubes timed at each move distance.
    #[arg(long, default_value_t = 50)]
    per_distance: usize,
    /// Builds of the table to take the median of.
    #[arg(long, default_value_t = 5)]
    builds: usize,
    /// Seed of the timed cubes.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

pub fn run(command: BenchCommand) -> anyhow::Result<ExitCode> {
    match command {
        BenchCommand::Solver(args) => solver(args),
        BenchCommand::Sim(args) => crate::bench_sim::run(args),
        BenchCommand::Env(args) => crate::bench_env::run(args),
        BenchCommand::Rl(args) => crate::bench_rl::run(args),
    }
}

#[derive(Serialize)]
struct SolverReport {
    table_build_ms: f64,
    ida_build_ms: f64,
    table_bytes: usize,
    ida_bytes: usize,
    per_distance: Vec<DistanceTiming>,
    seed: u64,
}

#[derive(Serialize)]
struct DistanceTiming {
    distance: usize,
    cubes: usize,
    table_median_us: f64,
    ida_median_us: f64,
    ida_over_table: f64,
}

fn median(mut samples: Vec<Duration>) -> Duration {
    samples.sort();
    samples[samples.len() / 2]
}

/// Median time of `f` over `runs` runs.
fn time_median(runs: usize, mut f: impl FnMut()) -> Duration {
    median(
        (0..runs.max(1))
            .map(|_| {
                let start = Instant::now();
                f();
                start.elapsed()
            })
            .collect(),
    )
}

/// Median over cubes of each cube's fastest of three solves.
fn solve_median(solver: &dyn Solver, cubes: &[Position]) -> Duration {
    let fastest_of_three = |p: &Position| {
        (0..3)
            .map(|_| {
                let start = Instant::now();
                black_box(solver.solve(p));
                start.elapsed()
            })
            .min()
            .unwrap_or_default()
    };
    median(cubes.iter().map(fastest_of_three).collect())
}

fn solver(args: SolverArgs) -> anyhow::Result<ExitCode> {
    let table_build = time_median(args.builds, || drop(black_box(DistanceTable::build())));
    let ida_build = time_median(args.builds, || drop(black_box(IdaStar::new())));
    let (table, ida) = (DistanceTable::build(), IdaStar::new());
    let per_distance = (1..=table.diameter())
        .map(|d| {
            let cubes: Vec<Position> =
                scrambles_at_distance(&table, d, args.per_distance, args.seed)
                    .iter()
                    .map(|s| Position::of(&s.facelets))
                    .collect();
            let (t, i) = (solve_median(&table, &cubes), solve_median(&ida, &cubes));
            DistanceTiming {
                distance: d,
                cubes: cubes.len(),
                table_median_us: t.as_secs_f64() * 1e6,
                ida_median_us: i.as_secs_f64() * 1e6,
                ida_over_table: i.as_secs_f64() / t.as_secs_f64().max(1e-12),
            }
        })
        .collect();
    let report = SolverReport {
        table_build_ms: table_build.as_secs_f64() * 1e3,
        ida_build_ms: ida_build.as_secs_f64() * 1e3,
        table_bytes: table.memory_bytes(),
        ida_bytes: ida.memory_bytes(),
        per_distance,
        seed: args.seed,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_solver(&report, &args);
    }
    Ok(ExitCode::SUCCESS)
}

fn print_solver(r: &SolverReport, args: &SolverArgs) {
    println!(
        "dexcube bench solver --per-distance {} --builds {} --seed {}",
        args.per_distance, args.builds, r.seed
    );
    println!(
        "table build (median of {}): {:.1} ms; IDA* pattern databases: {:.2} ms",
        args.builds, r.table_build_ms, r.ida_build_ms
    );
    let mib = |bytes: usize| bytes as f64 / (1 << 20) as f64;
    println!(
        "memory: table {:.2} MiB, IDA* {:.2} MiB",
        mib(r.table_bytes),
        mib(r.ida_bytes)
    );
    println!("distance  cubes  table median µs  IDA* median µs  IDA*/table");
    for d in &r.per_distance {
        println!(
            "{:>8}  {:>5}  {:>15.2}  {:>14.1}  {:>10.0}",
            d.distance, d.cubes, d.table_median_us, d.ida_median_us, d.ida_over_table
        );
    }
}
