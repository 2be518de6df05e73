//! The `dexcube` binary: a thin clap front end over the workspace's crates. Each subcommand
//! lives in its own module; errors print one clear line to stderr and exit with status 2.

mod bench;
mod bench_env;
mod bench_rl;
mod bench_sim;
mod demo;
mod distil;
mod env;
mod eval;
mod net;
mod recipe;
mod render;
mod solve;
mod stage;
mod train;
mod video;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Learning to solve a 2x2x2 Rubik's cube with a simulated Shadow Dexterous Hand.
#[derive(Parser)]
#[command(name = "dexcube", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    Solve(solve::SolveArgs),
    Scramble(solve::ScrambleArgs),
    Demo(demo::DemoArgs),
    Render(render::RenderArgs),
    Train(train::TrainArgs),
    Plot(train::PlotArgs),
    /// Averages the actor weights of several policies of one run, such as its snapshots, into
    /// one policy (stochastic weight averaging), with their normalisers pooled.
    Average(train::CombineArgs),
    /// Joins several policies of one stage into an ensemble that acts with the mean of their
    /// actions. The first gives the card (label, environment, view) and must observe at least
    /// as much as the others, which read the leading part of its observation.
    Ensemble(train::CombineArgs),
    /// Lets a training run's critics choose the action a policy takes: of its own action and
    /// a few near it, the one they value most (the smaller of TD3's two values). Writes a
    /// policy that loads and runs as any other.
    Guide(train::GuideArgs),
    /// Shows a policy its goal led on past the one it is judged by: once the angle still to
    /// go is small, a share of what is still to go is added to it, as a controller's integral
    /// term adds to an error that persists. Writes a policy that loads and runs as any other;
    /// its weights are unchanged.
    GoalLead(train::GoalLeadArgs),
    /// Shows a Stage 1 policy the cube in the frame nearest its goal: of the cube's rotations
    /// onto itself that its test cannot tell apart (in pair mode, the turns about the target's
    /// up axis and the flips), the one that leaves the cube's whole orientation nearest the
    /// goal's, at every step. Writes a policy that loads and runs as any other; its weights are
    /// unchanged.
    NearestFrame(train::NearestFrameArgs),
    /// Lets an ensemble hand a stalled episode to one of its members: once the cube has gone
    /// some steps neither meeting its test nor coming nearer its goal, that member acts alone
    /// for the rest of the episode (where the members would turn the cube different ways,
    /// their mean can turn it neither). Writes a policy that loads and runs as any other; its
    /// weights are unchanged.
    Handover(train::HandoverArgs),
    /// Ships a residual trained on top of a policy (`train --residual-of`) with that policy as
    /// one: it acts as the base, with the residual's correction added to each action.
    Residual(train::ResidualArgs),
    /// Lets a policy begin with a gesture where the cube starts towards the fingertips: for
    /// its first few steps, some actuators take a fixed action and the rest the neutral one,
    /// then the policy acts (Stage 2 mends most of its failures on that side of the palm with
    /// the knuckles straightened first). Writes a policy that loads and runs as any other; its
    /// weights are unchanged.
    StartGesture(train::StartGestureArgs),
    /// Lets an ensemble hand the episodes picked by where the cube starts to one member,
    /// acting alone throughout: those towards the thumb that make no start gesture, or (with
    /// --near-square) those that make it with the cube near square to the hand. Writes a policy
    /// that loads and runs as any other; its weights are unchanged.
    StartRoute(train::StartRouteArgs),
    /// Teaches one actor to act as a stage policy does (an ensemble, typically) by DAgger:
    /// the teacher labels every state of episodes run first by itself, then by the student.
    Distil(distil::DistilArgs),
    Eval(eval::EvalArgs),
    EvalStage(eval::EvalStageArgs),
    /// Inspects the training environments.
    #[command(subcommand)]
    Env(env::EnvCommand),
    /// Prints performance figures.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
}

fn main() -> ExitCode {
    // Output piped into a reader that stops early (`dexcube scramble ... | head`) ends the
    // program quietly, as for any Unix tool, rather than panicking on the closed pipe.
    #[cfg(unix)]
    // SAFETY: restoring the default action of one signal, before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    let outcome = match cli.command {
        Command::Solve(args) => solve::solve(args),
        Command::Scramble(args) => solve::scramble(args),
        Command::Demo(args) => demo::run(args),
        Command::Render(args) => render::run(args),
        Command::Env(command) => env::run(command),
        Command::Train(args) => train::run(args),
        Command::Plot(args) => train::plot(args),
        Command::Average(args) => train::combine(train::Combination::Average, args),
        Command::Ensemble(args) => train::combine(train::Combination::Ensemble, args),
        Command::Guide(args) => train::guide(args),
        Command::GoalLead(args) => train::goal_lead(args),
        Command::NearestFrame(args) => train::nearest_frame(args),
        Command::Handover(args) => train::handover(args),
        Command::Residual(args) => train::residual(args),
        Command::StartGesture(args) => train::start_gesture(args),
        Command::StartRoute(args) => train::start_route(args),
        Command::Distil(args) => distil::run(args),
        Command::Eval(args) => eval::eval(args),
        Command::EvalStage(args) => eval::eval_stage(args),
        Command::Bench(command) => bench::run(command),
    };
    match outcome {
        Ok(code) => code,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::from(2)
        }
    }
}
