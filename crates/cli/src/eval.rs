//! `dexcube eval` (Table I: the hand solving scrambles at each move distance, with and
//! without rollback) and `dexcube eval-stage` (each atomic action alone, with a 95% interval).

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use anyhow::{Context, bail};
use clap::Args;
use dexcube_cube::{CostTable, DistanceTable, scrambles_at_distance};
use dexcube_env::{
    ControlRate, Info, ObjectKind, RecordedFailure, RecordedStart, RotMode, SimulatedEnv, StartMix,
    StartPick, is_square, pose_goal,
};
use dexcube_operator::eval::{
    CubeResult, Hooks, PolicyFiles, markdown, plot, run_cube, table, wilson_interval,
};
use dexcube_operator::stages::{Driving, Steadying};
use dexcube_operator::{OperatorConfig, Planner, hand_price};
use dexcube_rl::Policy;
use dexcube_rl::checkpoint::{file_beside, write_atomically};
use dexcube_rl::policy::{PolicyCard, policy_file};
use dexcube_rl::start_file::{StartsOrigin, save_starts};
use dexcube_sim::cube::{CubeState, read_puzzle, turned_since};
use dexcube_sim::{Scene, SceneKind, Sim};
use indicatif::{ProgressBar, ProgressStyle};

use crate::env::{EnvKind, physics_spread, starts_for};
use crate::stage::{StageSetup, meets_paper_test};
use crate::video::Video;

/// Which operator runs the plan.
#[derive(Args, Clone, Copy)]
pub struct OperatorArgs {
    /// The paper's operator: the solver's first optimal plan, Stage 1 before every move, and
    /// each stage for its policy's whole episode. By default the operator plans for the hand:
    /// of the optimal plans, the one of fewest atomic actions; no Stage 1 when the face to
    /// turn is already up; Stage 1 ends once the pose has been held 5 steps, and may run up
    /// to 200 steps until it is; and the hand opens gradually from where the last stage left
    /// it.
    #[arg(long)]
    pub paper_operator: bool,
    /// End Stage 1 once the pose has been held for this many control steps (its success test
    /// passing at each); 0 runs Stage 1 for all its steps (--stage1-steps). Default: 5
    /// planning for the hand, 0 with --paper-operator.
    #[arg(long, value_name = "STEPS", value_parser = clap::value_parser!(u64).range(0..=100))]
    pub stage1_held: Option<u64>,
    /// How the hand opens before each stage, from where the last one left it. Default:
    /// gradual planning for the hand, at-once with --paper-operator.
    #[arg(long, value_enum)]
    pub opening: Option<Opening>,
    /// Planning for the hand, when Stage 1 is skipped for a face already up: `pose`, when
    /// Stage 1's whole test passes; `face`, when the face is up wherever the cube lies;
    /// `top`, when the move's layer pair is top and bottom, however tilted.
    #[arg(long, value_enum, default_value_t = AlreadyUp::Pose, conflicts_with = "paper_operator")]
    pub already_up: AlreadyUp,
    /// With rollback, Stage 1 also needs the cube in its good state (every cubelet in line):
    /// a cube it leaves with a layer skewed is squared up and re-posed by randomisation, as a
    /// pose that is off is, before Stage 2 tries to turn it.
    #[arg(long)]
    pub stage1_good_state: bool,
    /// Planning for the hand, price each plan's first move knowing which face is up now, so
    /// that of equally short plans one starting on that face (no Stage 1) is preferred.
    #[arg(long, conflicts_with = "paper_operator")]
    pub plan_from_face_up: bool,
    /// With rollback, read the puzzle after Stage 1 too: if a layer turned while the cube was
    /// re-posed, skip the move's Stage 2 and re-plan from what is there. The default planning
    /// for the hand (measured in Table I, session 32: as many cubes, fewer actions); off with
    /// --paper-operator.
    #[arg(long, overrides_with = "no_stage1_puzzle_check")]
    pub stage1_puzzle_check: bool,
    /// Without the check after Stage 1: the operator turns first and finds out after, from
    /// the move check, that the move did not happen (the default until session 32).
    #[arg(long, overrides_with = "stage1_puzzle_check")]
    pub no_stage1_puzzle_check: bool,
    /// Planning for the hand, take the cheapest plan of any length rather than of the optimal
    /// ones, with each U' turn priced 1 and each Stage 1 this many: a Stage 1 risks the cube
    /// more than a turn (in Table I, 1.4% of Stage 1 runs dropped it, 0.03% of Stage 2 runs).
    /// 1 takes the plan of fewest atomic actions. Measured in Table I it solved no more cubes
    /// than the default: the shipped Stage 2 leaves the cube tilted, so a move about the axis
    /// just turned needs a Stage 1 after all (results/TRAINING.md, session 14).
    #[arg(long, value_name = "TURNS", conflicts_with = "paper_operator",
          value_parser = clap::value_parser!(u32).range(1..=100))]
    pub stage1_price: Option<u32>,
    /// A reflex against drops: whenever the cube strays this far across the palm from its
    /// resting point during Stage 1, the hand takes the neutral action for --steady-steps
    /// control steps before the policy goes on. Off by default.
    #[arg(long, value_name = "METRES", value_parser = positive_metres)]
    pub steady_radius: Option<f64>,
    /// Control steps the hand holds still each time --steady-radius fires.
    #[arg(long, value_name = "STEPS", default_value_t = 5, requires = "steady_radius",
          value_parser = clap::value_parser!(u64).range(1..=100))]
    pub steady_steps: u64,
    /// Run Stage 1's policy acting every N physics substeps of 2 ms rather than at the rate
    /// it was trained at (the paper's 20; fewer is faster, as many more steps to a run). N
    /// divides 20. Off by default.
    #[arg(long = "stage1-control-substeps", value_name = "N")]
    pub stage1_control_rate: Option<ControlRate>,
    /// Run Stage 1 for up to this many control steps rather than its policy's episode (the
    /// paper's 100 at its rate), still ending once held: time for poses the policy reaches
    /// late. Counted at the paper's rate, as --stage1-held is. Default: 200 planning for the
    /// hand (since session 47; 100 reproduces the figures made before), the policy's episode
    /// with --paper-operator.
    #[arg(long, value_name = "STEPS", value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub stage1_steps: Option<u64>,
}

/// A distance in metres, above 0 and at most 0.2 (beyond that the cube is off the palm).
fn positive_metres(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(metres) if metres > 0.0 && metres <= 0.2 => Ok(metres),
        _ => Err(format!(
            "'{text}' is not a distance in metres above 0 and at most 0.2 (e.g. 0.03)"
        )),
    }
}

#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq)]
pub enum AlreadyUp {
    /// Stage 1's own test: the face up within 0.1 rad and the cube within 0.01 m of its
    /// resting point.
    Pose,
    /// The face up within 0.1 rad, anywhere on the palm.
    Face,
    /// The face or its opposite pointing more nearly up than any other, however the cube is
    /// tilted or placed: how the second and third turns of a U, R or F move begin anyway.
    Top,
}

impl AlreadyUp {
    fn rule(self) -> dexcube_operator::AlreadyUp {
        match self {
            AlreadyUp::Pose => dexcube_operator::AlreadyUp::Pose,
            AlreadyUp::Face => dexcube_operator::AlreadyUp::Face,
            AlreadyUp::Top => dexcube_operator::AlreadyUp::Top,
        }
    }
}

#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq)]
pub enum Opening {
    /// The targets jump to the flat hand.
    AtOnce,
    /// The targets move to the flat hand step by step over the settling steps.
    Gradual,
}

impl OperatorArgs {
    pub fn config(self, rollback: bool) -> OperatorConfig {
        let mut driving = if self.paper_operator {
            Driving::default()
        } else {
            Driving::FOR_HAND
        };
        if let Some(steps) = self.stage1_held {
            driving.stage1_held_steps = (steps > 0).then_some(steps as usize);
        }
        if let Some(opening) = self.opening {
            driving.gradual_opening = opening == Opening::Gradual;
        }
        driving.stage1_steadying = self.steady_radius.map(|radius| Steadying {
            radius,
            steps: self.steady_steps as usize,
        });
        driving.stage1_control_rate = self.stage1_control_rate;
        if let Some(steps) = self.stage1_steps {
            driving.stage1_steps = Some(steps as usize);
        }
        OperatorConfig {
            rollback,
            plan_for_hand: !self.paper_operator,
            driving,
            already_up: self.already_up.rule(),
            stage1_good_state: self.stage1_good_state,
            plan_from_face_up: self.plan_from_face_up,
            stage1_puzzle_check: self.puzzle_check(),
            ..OperatorConfig::default()
        }
    }

    /// The operator's name in a run's record: "paper" for the paper's own (as Table I's
    /// record names it), otherwise its planner and how it drives the policies.
    fn name(self) -> String {
        let config = self.config(true);
        let driving = config.driving;
        if self.paper_operator
            && driving == Driving::default()
            && !config.stage1_good_state
            && !config.stage1_puzzle_check
        {
            return "paper".to_string();
        }
        let planner = if self.paper_operator {
            "paper"
        } else {
            "planning for the hand"
        };
        let opening = if driving.gradual_opening {
            "gradually"
        } else {
            "at once"
        };
        let stage1 = match driving.stage1_held_steps {
            Some(steps) => format!("Stage 1 ends once held {steps} steps"),
            None => "whole Stage 1 episodes".to_string(),
        };
        let skip = match self.already_up {
            AlreadyUp::Pose => "",
            AlreadyUp::Face => ", no Stage 1 when the face is up anywhere on the palm",
            AlreadyUp::Top => ", no Stage 1 when the layer pair is top and bottom",
        };
        let square = when(
            config.stage1_good_state,
            ", Stage 1 also needs the good state",
        );
        let first_move = when(
            config.plan_from_face_up,
            ", the first move priced knowing the face up",
        );
        let puzzle_check = when(
            config.stage1_puzzle_check,
            ", the puzzle checked after Stage 1",
        );
        let any_length = self.stage1_price.map_or(String::new(), |price| {
            format!(", plans of any length with a Stage 1 priced {price} turns")
        });
        let steadying = driving.stage1_steadying.map_or(String::new(), |s| {
            format!(
                ", Stage 1 holds still {} steps when the cube strays {} m",
                s.steps, s.radius
            )
        });
        let rate = driving.stage1_control_rate.map_or(String::new(), |n| {
            format!(", Stage 1 acting every {n} substeps")
        });
        let budget = driving.stage1_steps.map_or(String::new(), |steps| {
            format!(", Stage 1 up to {steps} steps")
        });
        format!(
            "{planner}{any_length}, opening the hand {opening}, {stage1}{rate}{budget}{steadying}{skip}{square}{puzzle_check}{first_move}"
        )
    }

    /// Whether the rollback reads the puzzle after Stage 1: as asked, else planning for the
    /// hand and not with the paper's operator.
    fn puzzle_check(self) -> bool {
        match (self.stage1_puzzle_check, self.no_stage1_puzzle_check) {
            (true, _) => true,
            (false, true) => false,
            (false, false) => !self.paper_operator,
        }
    }

    /// The cost table for plans of any length, when a Stage 1 price asks for them (a couple of
    /// seconds to build).
    pub fn hand_plans(self) -> Option<CostTable> {
        self.stage1_price
            .map(|price| CostTable::build(hand_price(price)))
    }

    /// The flags that select this operator, as a command line names them.
    fn flags(self) -> String {
        let paper = when(self.paper_operator, " --paper-operator");
        let held = self
            .stage1_held
            .map_or(String::new(), |steps| format!(" --stage1-held {steps}"));
        let opening = match self.opening {
            Some(Opening::AtOnce) => " --opening at-once",
            Some(Opening::Gradual) => " --opening gradual",
            None => "",
        };
        let already_up = match self.already_up {
            AlreadyUp::Pose => "",
            AlreadyUp::Face => " --already-up face",
            AlreadyUp::Top => " --already-up top",
        };
        let square = when(self.stage1_good_state, " --stage1-good-state");
        let first_move = when(self.plan_from_face_up, " --plan-from-face-up");
        let puzzle_check = match (self.puzzle_check(), self.paper_operator) {
            (true, true) => " --stage1-puzzle-check",
            (false, false) => " --no-stage1-puzzle-check",
            _ => "",
        };
        let price = self
            .stage1_price
            .map_or(String::new(), |price| format!(" --stage1-price {price}"));
        let steady = self.steady_radius.map_or(String::new(), |radius| {
            format!(
                " --steady-radius {radius} --steady-steps {}",
                self.steady_steps
            )
        });
        let rate = self
            .stage1_control_rate
            .map_or(String::new(), |n| format!(" --stage1-control-substeps {n}"));
        let budget = self
            .stage1_steps
            .map_or(String::new(), |steps| format!(" --stage1-steps {steps}"));
        format!(
            "{paper}{held}{opening}{already_up}{square}{puzzle_check}{first_move}{price}{steady}{rate}{budget}"
        )
    }
}

/// `text` when `on`, else nothing: an optional part of an operator's name or flags.
fn when(on: bool, text: &str) -> &str {
    if on { text } else { "" }
}

/// The shipped policies, or others.
#[derive(Args, Clone)]
pub struct PolicyArgs {
    /// Stage 1 policy (prefix of NAME.safetensors and NAME.json).
    #[arg(long, default_value = "models/rot")]
    pub rot_policy: PathBuf,
    /// Stage 2 (U') policy.
    #[arg(long, default_value = "models/layer")]
    pub layer_policy: PathBuf,
}

impl PolicyArgs {
    /// The policy files, checked to exist, with Stage 1's mode read from its card.
    pub fn files(&self) -> anyhow::Result<PolicyFiles> {
        for prefix in [&self.rot_policy, &self.layer_policy] {
            let card = policy_file(prefix, "json");
            if !card.is_file() {
                bail!(
                    "no policy at {}: the shipped ones are under models/ (git checkout models), or train one \
                     with `dexcube train rot` / `dexcube train layer` and pass its policy (DIR/policy)",
                    card.display()
                );
            }
        }
        let card_path = policy_file(&self.rot_policy, "json");
        let card: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&card_path)?)
                .with_context(|| format!("{} is not a policy card (JSON)", card_path.display()))?;
        Ok(PolicyFiles {
            rot: self.rot_policy.clone(),
            layer: self.layer_policy.clone(),
            rot_mode: rot_mode_of(&card)
                .with_context(|| format!("reading Stage 1's mode from {}", card_path.display()))?,
        })
    }
}

/// The CubeRotEnv success test a Stage 1 card was trained with: its `mode`, or for cards
/// written before that field the first word of its variant ("pair" of "pair-cube"). A card
/// that names neither was trained in the paper's mode.
fn rot_mode_of(card: &serde_json::Value) -> anyhow::Result<RotMode> {
    let environment = &card["metadata"]["environment"];
    let named = environment["mode"]
        .as_str()
        .or_else(|| environment["variant"].as_str()?.split('-').next());
    match named {
        Some(mode) => mode.parse().map_err(anyhow::Error::msg),
        None => Ok(RotMode::Paper),
    }
}

/// Solves scrambled cubes with the hand: success rate and action number per move distance.
#[derive(Args)]
pub struct EvalArgs {
    /// Cubes per move distance (the paper: 100).
    #[arg(long, default_value_t = 100)]
    per_distance: usize,
    /// Move distances, e.g. 1-14 or 3,5,7.
    #[arg(long, default_value = "1-14")]
    distances: String,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Only the open-loop variant (default: both, rollback first).
    #[arg(long, conflicts_with = "rollback_only")]
    no_rollback: bool,
    /// Only the rollback variant.
    #[arg(long)]
    rollback_only: bool,
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Output prefix: PREFIX.csv (one row per cube; a rerun continues it), PREFIX.md,
    /// PREFIX-sr.png, PREFIX-an.png.
    #[arg(long, default_value = "results/table1")]
    out: PathBuf,
    #[command(flatten)]
    policies: PolicyArgs,
    #[command(flatten)]
    operator: OperatorArgs,
    /// Also record where every Stage 1 run began (the physics state once the hand has
    /// opened, and the pose asked for) into this file, each marked failed if the run dropped
    /// the cube or ended without the pose the check after Stage 1 accepts, for
    /// a recipe phase's `starts` and `eval-stage rot --starts`. Needs a fresh --out.
    #[arg(long, value_name = "FILE")]
    record_starts: Option<PathBuf>,
    /// Also record where every Stage 2 run began (the physics state once the hand has
    /// opened) into this file, each marked failed if the run did not leave the layer turned
    /// with the cube square, for a recipe phase's `starts` and `eval-stage layer --starts`.
    /// Needs a fresh --out.
    #[arg(long, value_name = "FILE")]
    record_layer_starts: Option<PathBuf>,
}

fn parse_distances(text: &str) -> anyhow::Result<Vec<usize>> {
    let mut out = Vec::new();
    for part in text.split(',') {
        let part = part.trim();
        let range: Vec<&str> = part.split('-').collect();
        let (lo, hi): (usize, usize) = match range.as_slice() {
            [one] => (one.parse()?, one.parse()?),
            [lo, hi] => (lo.parse()?, hi.parse()?),
            _ => bail!("cannot read move distances '{text}': use e.g. 1-14 or 3,5,7"),
        };
        if lo < 1 || hi > 14 || lo > hi {
            bail!("move distances run from 1 to 14; got '{part}'");
        }
        out.extend(lo..=hi);
    }
    Ok(out)
}

pub fn eval(args: EvalArgs) -> anyhow::Result<ExitCode> {
    let distances = parse_distances(&args.distances)?;
    let files = args.policies.files()?;
    let variants: Vec<bool> = match (args.no_rollback, args.rollback_only) {
        (true, _) => vec![false],
        (_, true) => vec![true],
        _ => vec![true, false],
    };
    let table_all = DistanceTable::build();
    let hand_plans = args.operator.hand_plans();
    let planner = Planner {
        optimal: &table_all,
        any_length: hand_plans.as_ref(),
    };
    let csv = table_file(&args.out, "csv");
    check_same_run(&args.out, &files, args.seed, args.operator)?;
    let mut results: Vec<CubeResult> = std::fs::read_to_string(&csv)
        .map(|text| {
            text.lines()
                .skip(1)
                .filter_map(CubeResult::from_csv)
                .collect()
        })
        .unwrap_or_default();
    let done: HashSet<(usize, usize, bool)> = results
        .iter()
        .map(|r| (r.distance, r.index, r.rollback))
        .collect();
    let mut jobs = Vec::new();
    for &rollback in &variants {
        for &d in &distances {
            for (i, s) in scrambles_at_distance(&table_all, d, args.per_distance, args.seed)
                .into_iter()
                .enumerate()
            {
                if !done.contains(&(d, i, rollback)) {
                    jobs.push((d, i, rollback, s.moves));
                }
            }
        }
    }
    // The command that makes the rows on file: a CSV continued with the other variant holds
    // both, as one run without --rollback-only or --no-rollback makes them.
    let command = |rows: &[CubeResult]| {
        let variant = match (
            rows.iter().any(|r| r.rollback),
            rows.iter().any(|r| !r.rollback),
        ) {
            (true, false) => " --rollback-only",
            (false, true) => " --no-rollback",
            _ => "",
        };
        format!(
            "dexcube eval --per-distance {} --distances {} --seed {}{variant}{} --rot-policy {} --layer-policy {}",
            args.per_distance,
            args.distances,
            args.seed,
            args.operator.flags(),
            files.rot.display(),
            files.layer.display()
        )
    };
    let recording = [
        (EnvKind::Rot, &args.record_starts),
        (EnvKind::Layer, &args.record_layer_starts),
    ];
    if recording.iter().any(|(_, path)| path.is_some()) && !results.is_empty() {
        bail!(
            "recording starts records every cube of a run, and {} already holds {} of them: pass a new --out",
            csv.display(),
            results.len()
        );
    }
    eprintln!(
        "{} cubes to go ({} already in {})",
        jobs.len(),
        results.len(),
        csv.display()
    );
    let bar = ProgressBar::new(jobs.len() as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "[{elapsed_precise}] {wide_bar} {pos}/{len} cubes, ETA {eta} {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let scene = Scene::load(SceneKind::Cube)?;
    let resting = dexcube_operator::eval::resting_point()?;
    let shared = Mutex::new(std::mem::take(&mut results));
    let recorded = Mutex::new(Vec::new());
    let save = |results: &[CubeResult]| -> anyhow::Result<()> {
        let mut sorted = results.to_vec();
        sorted.sort_by_key(|r| (!r.rollback, r.distance, r.index));
        let text: Vec<String> = std::iter::once(CubeResult::CSV_HEADER.to_string())
            .chain(sorted.iter().map(CubeResult::csv_row))
            .collect();
        write_atomically(&csv, (text.join("\n") + "\n").as_bytes())?;
        let rows = table(&sorted, &distances);
        write_atomically(
            &table_file(&args.out, "md"),
            markdown(&rows, &sorted, &command(&sorted)).as_bytes(),
        )?;
        Ok(())
    };
    let done = in_parallel(
        args.threads,
        jobs.len(),
        || Ok(files.load(resting)?),
        |stages, k| {
            let (d, i, rollback, moves) = &jobs[k];
            let seed = args.seed ^ ((*d as u64) << 40) ^ ((*i as u64) << 8) ^ (*rollback as u64);
            let (mut starts1, mut starts2) = (Vec::new(), Vec::new());
            let hooks = Hooks {
                watch: &mut |_| {},
                narrate: &mut |_| {},
                stage1_starts: args.record_starts.is_some().then_some(&mut starts1),
                stage2_starts: args.record_layer_starts.is_some().then_some(&mut starts2),
            };
            let job = (moves.as_slice(), args.operator.config(*rollback), seed);
            let outcome = run_cube(stages, &scene, planner, job, hooks);
            recorded.lock().expect("lock").push((k, [starts1, starts2]));
            let row = CubeResult {
                distance: *d,
                index: *i,
                rollback: *rollback,
                solved: outcome.solved,
                actions: outcome.actions,
                randomisations: outcome.randomisations,
                replans: outcome.replans,
                control_steps: outcome.control_steps,
                failure: outcome.failure_text(),
                stages: Some(outcome.stages),
            };
            let mut all = shared.lock().expect("lock");
            all.push(row);
            let solved = all.iter().filter(|r| r.solved).count();
            bar.set_message(format!("solved {solved}/{}", all.len()));
            bar.inc(1);
            // Every finished cube is on disk at once: a killed run loses at most the cubes
            // under way.
            save(&all)
        },
    );
    bar.finish();
    done?;
    let results = shared.into_inner().expect("lock");
    save(&results)?;
    let mut recorded = in_episode_order(recorded);
    let record_flags: String = recording
        .iter()
        .filter_map(|(stage, path)| {
            let path = path.as_ref()?;
            Some(format!(" {} {}", stage.record_flag(), path.display()))
        })
        .collect();
    for (stage_index, (stage, path)) in recording.into_iter().enumerate() {
        let Some(path) = path else { continue };
        let starts: Vec<_> = recorded
            .iter_mut()
            .flat_map(|s| std::mem::take(&mut s[stage_index]))
            .collect();
        let (name, failure) = (stage.stage(), stage.recorded_failure());
        if starts.is_empty() {
            bail!(
                "no {name} run began with the hand open in these cubes, so {} was not written: \
                 record over more cubes or longer move distances",
                path.display()
            );
        }
        let origin = StartsOrigin {
            stage: stage.name().to_string(),
            failure,
            scene: SceneKind::Cube.name().to_string(),
            command: format!("{}{record_flags}", command(&results)),
        };
        save_starts(path, &starts, &origin)?;
        let failed = starts.iter().filter(|s| s.failed).count();
        eprintln!(
            "recorded {} {name} starts (from {failed} of which the policy {}) in {}",
            starts.len(),
            failure.describe(),
            path.display()
        );
    }
    let rows = table(&results, &distances);
    if let Err(e) = plot(&rows, &table_file(&args.out, "md")) {
        eprintln!("warning: no plot: {e}");
    }
    print!("{}", markdown(&rows, &results, &command(&results)));
    Ok(ExitCode::SUCCESS)
}

/// Runs `work(state, k)` for every k in 0..n on `threads` threads. Each thread makes its own
/// state with `init` (a policy, an environment) and takes the next k as it frees up. The
/// first error is returned once every thread has stopped.
pub(crate) fn in_parallel<S>(
    threads: usize,
    n: usize,
    init: impl Fn() -> anyhow::Result<S> + Sync,
    work: impl Fn(&mut S, usize) -> anyhow::Result<()> + Sync,
) -> anyhow::Result<()> {
    let next = AtomicUsize::new(0);
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads.max(1))
            .map(|_| {
                s.spawn(|| -> anyhow::Result<()> {
                    let mut state = init()?;
                    loop {
                        let k = next.fetch_add(1, Ordering::Relaxed);
                        if k >= n {
                            return Ok(());
                        }
                        work(&mut state, k)?;
                    }
                })
            })
            .collect();
        handles.into_iter().try_for_each(|h| {
            h.join()
                .map_err(|_| anyhow::anyhow!("an evaluation thread panicked"))?
        })
    })
}

/// What `in_parallel`'s work gathered as (k, item), in the order of k.
fn in_episode_order<T>(gathered: Mutex<Vec<(usize, T)>>) -> Vec<T> {
    let mut gathered = gathered.into_inner().expect("no thread panics");
    gathered.sort_by_key(|(k, _)| *k);
    gathered.into_iter().map(|(_, item)| item).collect()
}

/// The file with `extension` (csv, md, run.json) of the table at `out`: `--out
/// results/lead0.5` writes `results/lead0.5.csv`, and `--out results/table.csv` names the same
/// table as `--out results/table`.
fn table_file(out: &Path, extension: &str) -> PathBuf {
    file_beside(out, extension, &["csv", "md"])
}

/// A 64-bit FNV-1a fingerprint of a file's bytes.
fn fingerprint(path: &Path) -> anyhow::Result<String> {
    let bytes = std::fs::read(path)
        .with_context(|| format!("reading {} to fingerprint it", path.display()))?;
    let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    });
    Ok(format!("{hash:016x}"))
}

/// A rerun may only continue PREFIX.csv if it was made with the same policies (by content:
/// the weights, and a guide's, goal lead's or handover's settings from the card), seed and
/// operator; PREFIX.run.json records them. More cubes per distance, or more distances, are
/// fine: scrambles at a seed are prefix-stable.
fn check_same_run(
    out: &Path,
    files: &PolicyFiles,
    seed: u64,
    operator: OperatorArgs,
) -> anyhow::Result<()> {
    let mut identity = serde_json::json!({
        "seed": seed,
        "operator": operator.name(),
        "rot_policy": fingerprint(&policy_file(&files.rot, "safetensors"))?,
        "layer_policy": fingerprint(&policy_file(&files.layer, "safetensors"))?,
    });
    for (key, prefix) in [("rot_acting", &files.rot), ("layer_acting", &files.layer)] {
        let card = PolicyCard::read(prefix)
            .with_context(|| format!("reading the card of {}", prefix.display()))?;
        if let Some(settings) = card.acting_settings() {
            identity[key] = settings;
        }
    }
    let (csv, sidecar) = (table_file(out, "csv"), table_file(out, "run.json"));
    if csv.exists() {
        let before: Option<serde_json::Value> = std::fs::read_to_string(&sidecar)
            .ok()
            .and_then(|text| serde_json::from_str(&text).ok());
        if before.as_ref() != Some(&identity) {
            bail!(
                "{} holds results of other policies, another seed or another operator (see {}); pass another --out, \
                 or delete it to start again",
                csv.display(),
                sidecar.display()
            );
        }
    }
    write_atomically(
        &sidecar,
        serde_json::to_string_pretty(&identity)?.as_bytes(),
    )?;
    Ok(())
}

/// Success rate of one atomic action alone, with a 95% confidence interval.
#[derive(Args)]
pub struct EvalStageArgs {
    #[arg(value_enum)]
    /// rot: Stage 1, CubeRotEnv with the policy's own success test and the paper's three
    /// targets; layer: Stage 2, LayerOpEnv U' with the goal exactly +90°.
    stage: EnvKind,
    #[arg(long, default_value_t = 1000)]
    episodes: usize,
    /// Episode i is reset with seed + i.
    #[arg(long, default_value_t = 1_000_000)]
    seed: u64,
    #[arg(long, default_value_t = 2)]
    threads: usize,
    #[command(flatten)]
    policies: PolicyArgs,
    /// Stage 2's object: cube or block (default: the one the policy was trained on).
    #[arg(long)]
    object: Option<ObjectKind>,
    /// Also write the result into the policy's JSON card, as its evaluation.
    #[arg(long, conflicts_with = "starts")]
    record: bool,
    /// Begin episode k from recorded start k of this file, where the operator handed the
    /// stage the cube (made by `eval --record-starts` for rot, `eval --record-layer-starts`
    /// for layer), rather than from a fresh placement seeded seed + k. Runs the first
    /// min(--episodes, starts) of them.
    #[arg(long, value_name = "FILE")]
    starts: Option<PathBuf>,
    /// Also record where every episode began (the physics state after its fresh reset, and
    /// its goal) into this file, each marked failed as `eval` marks the stage's starts, for
    /// `train --starts`: training can then draw the placements this policy failed from more
    /// often. Record with seeds that no evaluation uses.
    #[arg(long, value_name = "FILE")]
    record_starts: Option<PathBuf>,
    /// With --record-starts and a policy with a start gesture (`dexcube start-gesture`):
    /// record an episode that makes the gesture where the policy first acts after it (the
    /// physics state after the gesture's last step, the goal, the angle the layer turned
    /// meanwhile and the face whose layer turns), so that `train --starts` can teach the
    /// policy's actor, which makes no gesture, from where the gesture leaves the cube. Such
    /// starts are for the actor alone: replayed with the gesturing policy, the gesture would
    /// be made twice.
    #[arg(long, requires = "record_starts")]
    after_gesture: bool,
    /// Stage 1 only: also record, for every episode that missed its pose and kept the cube,
    /// where it came closest to the pose (the physics state after the step with the smallest
    /// angle from the goal, and the goal), marked failed, for `train --starts`: the states
    /// this policy lost its pose from, or came nearest it and fell short, rather than where
    /// the cube was placed.
    #[arg(long, value_name = "FILE")]
    record_closest: Option<PathBuf>,
    /// Stage 1 only, for an ensemble that hands over (`dexcube handover`): also record, for
    /// every episode it handed to its member, the physics state the member first acted from,
    /// and the goal, marked failed where the episode then failed, for `train --starts`: where
    /// the member is handed the cube.
    #[arg(long, value_name = "FILE")]
    record_handovers: Option<PathBuf>,
    /// Stage 1 only: also record, for every episode whose cube strays more than
    /// --stray-radius from its goal's position before any handover, the physics state after
    /// the first such step, and the goal, marked failed where the episode then failed, for
    /// `train --starts`: where the cube is on its way off the palm (session 60).
    #[arg(long, value_name = "FILE")]
    record_strays: Option<PathBuf>,
    /// How far from its goal's position (metres) a cube has strayed for --record-strays.
    #[arg(
        long,
        default_value_t = 0.05,
        value_name = "M",
        requires = "record_strays",
        value_parser = stray_radius
    )]
    stray_radius: f64,
    /// Let the policy act every N physics substeps of 2 ms (the paper's 20; fewer is a
    /// faster control rate), with as many more steps to an episode, so that each still
    /// lasts 4 simulated seconds; placements and settling are unchanged. N divides 20.
    /// Default: the rate the policy was trained at. Only that rate can be --record'ed.
    #[arg(long = "control-substeps", value_name = "N")]
    control_rate: Option<ControlRate>,
    /// Vary each episode's physics by this spread S, drawn from the episode's seed as `train
    /// --physics-spread` draws it (friction, the object's mass and joint damping, each scaled
    /// between 1/(1+S) and 1+S): how a policy fares on physics other than the one it is
    /// judged on. 0, the default, is the scene's own physics, the only one --record writes.
    #[arg(long, default_value_t = 0.0, value_name = "S", value_parser = physics_spread)]
    physics_spread: f64,
    /// Run each episode for N control steps and judge it at the last, rather than for the
    /// paper's 4 simulated seconds (100 steps at its rate): whether a policy's misses are
    /// slow turns or poses, or ones more time does not mend. Only the paper's length can be
    /// --record'ed.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    episode_steps: Option<u64>,
    /// Also write a video of the first episode (.gif, or .mp4 with ffmpeg installed): it is
    /// run once more on its own, as it ran among the others, to watch what the hand did.
    #[arg(long, value_name = "FILE")]
    video: Option<PathBuf>,
    /// Also write one CSV row per episode: its number, seed (or recorded start), ending,
    /// final position and angle errors, whether the cube ended square and with a layer
    /// turned, its longest run of steps at the goal, its angle from the goal at the start,
    /// the first step that met the paper's test (empty if none did), Stage 1's final angle
    /// with the pose read from all eight cubelets (empty for the others), and whether an
    /// ensemble that hands over (`dexcube handover`) handed the episode to its member.
    #[arg(long, value_name = "FILE.csv")]
    episodes_csv: Option<PathBuf>,
}

/// How an episode of one atomic action ended: success, or the reason it missed.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Ending {
    Success,
    Dropped,
    /// Orientation (or layer angle) reached, position not.
    PositionOff,
    /// Position reached, orientation (or layer angle) not.
    AngleOff,
    BothOff,
    /// Stage 2: the layer ended within 22.5° of where it began (it never turned).
    NeverTurned,
    /// Stage 2 on the physical cube: the layer never turned, and the cube ended out of its
    /// good state (another layer gave way, or the layer stuck part-way).
    Jammed,
}

impl Ending {
    const ALL: [Ending; 7] = [
        Ending::Success,
        Ending::Dropped,
        Ending::PositionOff,
        Ending::AngleOff,
        Ending::BothOff,
        Ending::NeverTurned,
        Ending::Jammed,
    ];

    /// The ending's name in a CSV column.
    fn tag(self) -> &'static str {
        match self {
            Ending::Success => "success",
            Ending::Dropped => "dropped",
            Ending::PositionOff => "position_off",
            Ending::AngleOff => "angle_off",
            Ending::BothOff => "both_off",
            Ending::NeverTurned => "never_turned",
            Ending::Jammed => "jammed",
        }
    }

    fn name(self) -> &'static str {
        match self {
            Ending::Success => "success",
            Ending::Dropped => "dropped or blew up",
            Ending::PositionOff => "missed on position only",
            Ending::AngleOff => "missed on angle only",
            Ending::BothOff => "missed on both",
            Ending::NeverTurned => "missed: the layer never turned (within 22.5° of its start)",
            Ending::Jammed => {
                "missed: the layer never turned, and the cube ended out of its good state"
            }
        }
    }

    /// Stage 2's misses by an angle error of more than 67.5° from the quarter turn are the
    /// layer never turning (`turning` is true for Stage 2), told apart by whether the cube
    /// ended `square` (in its good state; a rigid object always is).
    fn of(info: &Info, thresholds: (f64, f64), turning: bool, square: bool) -> Ending {
        if meets_paper_test(info, thresholds) {
            return Ending::Success;
        }
        let (position, angle) = thresholds;
        if info.dropped || info.physics_error.is_some() {
            return Ending::Dropped;
        }
        if turning && info.angle_error > 3.0 * std::f64::consts::FRAC_PI_8 {
            return if square {
                Ending::NeverTurned
            } else {
                Ending::Jammed
            };
        }
        match (info.position_error >= position, info.angle_error >= angle) {
            (true, false) => Ending::PositionOff,
            (false, true) => Ending::AngleOff,
            _ => Ending::BothOff,
        }
    }
}

/// One deterministic episode of an atomic action: its last step's info, whether the object
/// ended square (a physical cube in its good state; any other object always), the longest
/// run of consecutive steps at the goal before the end (or before a drop), how far from the
/// goal it began and the first step that met the paper's test.
struct EpisodeTrace {
    /// Stage 1 on the physical cube: the final angle from the goal with the cube's pose read
    /// from all eight cubelets (`CubeState::mean_frame`) rather than DBL's alone.
    mean_frame_angle_error: Option<f64>,
    info: Info,
    /// The angle from the goal when the episode began (radians).
    start_angle_error: f64,
    /// The first control step (counted from 1) at the end of which the paper's test was met.
    first_at_goal: Option<usize>,
    square: bool,
    /// The physical cube ended with a layer turned from where it began.
    turned_a_layer: bool,
    longest_hold: usize,
    /// Where the episode began, when asked for (a fresh reset's).
    start: Option<RecordedStart>,
    /// Where it came closest to its goal (the state after the step with the smallest angle
    /// from it), when asked for; Stage 1 only, whose goal holds through the episode.
    closest: Option<RecordedStart>,
    /// Where an ensemble that hands over handed the episode to its member, when asked for;
    /// Stage 1 only, as for `closest`.
    handover: Option<RecordedStart>,
    /// Where the cube first strayed past the radius asked for, before any handover; Stage 1
    /// only, as for `closest`.
    stray: Option<RecordedStart>,
    /// The member an ensemble with a handover handed the episode to, if it did.
    handed_to: Option<usize>,
    /// A policy with a start gesture made it before it first acted.
    gestured: bool,
    /// Which of a policy's start routes handed the episode to its member, if any.
    route: Option<usize>,
}

fn stray_radius(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(radius) if radius > 0.0 => Ok(radius),
        _ => Err(format!(
            "--stray-radius must be a distance in metres above 0, not '{text}'"
        )),
    }
}

/// What an episode keeps of its physics, for `--record-starts` (where the policy first acts
/// after its start gesture with `--after-gesture`), `--record-closest` and
/// `--record-handovers`.
#[derive(Clone, Copy, Default)]
struct Keep {
    start: bool,
    after_gesture: bool,
    closest: bool,
    handover: bool,
    /// The radius for `--record-strays`, when asked for.
    stray: Option<f64>,
}

/// Runs a deterministic episode from `seed`, keeping what `keep` asks for; `posing` for
/// Stage 1, whose goal is a pose.
fn episode(
    env: &mut dyn SimulatedEnv,
    policy: &Policy,
    seed: u64,
    thresholds: (f64, f64),
    keep: Keep,
    posing: bool,
    watch: &mut dyn FnMut(&mut Sim),
) -> EpisodeTrace {
    let (mut obs, start_info) = env.reset(Some(seed));
    let mut start = keep.start.then(|| env.fresh_start());
    let puzzle_at_start = read_puzzle(env.sim());
    let (mut hold, mut longest_hold) = (0, 0);
    let (mut steps, mut first_at_goal) = (0, None);
    let (mut closest, mut closest_angle) = (None, f64::INFINITY);
    let (mut handover, mut stray) = (None, None);
    watch(env.sim_mut());
    let test = env.goal();
    let mut acting = policy.episode();
    loop {
        let achieved = || obs.achieved_goal.clone();
        let action =
            acting.act_toward(&obs.observation, &obs.desired_goal, achieved, test.as_ref());
        if keep.handover && handover.is_none() && acting.handed_over() {
            // The state the member first acts from, before its first step.
            handover = Some(env.fresh_start());
        }
        let t = env.step(&action);
        watch(env.sim_mut());
        steps += 1;
        if keep.after_gesture && acting.gesture_just_made() {
            start = Some(env.fresh_start());
        }
        hold = if meets_paper_test(&t.info, thresholds) {
            first_at_goal.get_or_insert(steps);
            hold + 1
        } else {
            0
        };
        longest_hold = longest_hold.max(hold);
        if let Some(radius) = keep.stray
            && stray.is_none()
            && !acting.handed_over()
            && t.info.position_error > radius
            && !t.info.dropped
        {
            stray = Some(env.fresh_start());
        }
        if keep.closest && t.info.angle_error < closest_angle {
            closest_angle = t.info.angle_error;
            // Stage 1's goal is the same at every step, so this restores the moment.
            closest = Some(env.fresh_start());
        }
        if t.terminated || t.truncated {
            let mean_frame_angle_error =
                posing
                    .then(|| CubeState::read(env.sim()))
                    .flatten()
                    .map(|cube| {
                        let mut achieved = t.observation.achieved_goal.clone();
                        let pose = pose_goal(cube.pose().position, cube.mean_frame());
                        achieved[..pose.len()].copy_from_slice(&pose);
                        test.errors(&achieved, &t.observation.desired_goal).1
                    });
            return EpisodeTrace {
                mean_frame_angle_error,
                square: is_square(env.sim()),
                turned_a_layer: turned_since(puzzle_at_start.as_ref(), env.sim()),
                info: t.info,
                start_angle_error: start_info.angle_error,
                first_at_goal,
                longest_hold,
                start,
                closest,
                handover,
                stray,
                handed_to: acting.handed_to(),
                gestured: acting.gestured(),
                route: acting.route(),
            };
        }
        obs = t.observation;
    }
}

/// Holds of at least this many control steps are counted in `eval-stage`'s report: what a
/// stage that stopped once its goal had been held that long would have scored.
const HOLDS: [usize; 3] = [1, 10, 25];

pub fn eval_stage(args: EvalStageArgs) -> anyhow::Result<ExitCode> {
    let files = args.policies.files()?;
    let endings: [AtomicUsize; 7] = Default::default();
    let held: [AtomicUsize; HOLDS.len()] = Default::default();
    let wins_out_of_square = AtomicUsize::new(0);
    // Stage 1 episodes that kept the cube and ended with a layer turned, and of them successes.
    let (layer_turns, successes_with_layer_turns) = (AtomicUsize::new(0), AtomicUsize::new(0));
    // Episodes that began with a start gesture, and of them successes.
    let gestured: [AtomicUsize; 2] = Default::default();
    let mut setup = StageSetup::new(args.stage, &files, args.object, args.control_rate)?;
    let (thresholds, control_rate) = (setup.thresholds, setup.settings.rate);
    if args.record && args.physics_spread > 0.0 {
        bail!(
            "--record writes the policy's evaluation on the scene's own physics, not under \
             --physics-spread {}: drop one of the two",
            args.physics_spread
        );
    }
    setup.settings.physics_spread = args.physics_spread;
    if args.record && args.episode_steps.is_some() {
        bail!(
            "--record writes the policy's evaluation over the paper's episode, not over \
             --episode-steps: drop one of the two"
        );
    }
    setup.settings.episode_steps = args.episode_steps.map(|steps| steps as usize);
    for (flag, asked) in [
        ("--record-closest", args.record_closest.is_some()),
        ("--record-handovers", args.record_handovers.is_some()),
        ("--record-strays", args.record_strays.is_some()),
    ] {
        if asked && args.stage != EnvKind::Rot {
            bail!(
                "{flag} keeps Stage 1's states, whose goal holds through an episode; Stage 2 \
                 counts its goal from where the layer lay at the start: record Stage 2's inner \
                 states with the stage2_jams example's --keep-jams"
            );
        }
    }
    if args.record && control_rate != setup.trained_rate {
        bail!(
            "--record writes the policy's evaluation at the rate it was trained at ({} \
             substeps), not at {control_rate}: drop --control-substeps or --record",
            setup.trained_rate
        );
    }
    let (prefix, object, scene) = (setup.prefix.clone(), setup.object, setup.scene.clone());
    let card = PolicyCard::read(&prefix)?;
    // Episodes an ensemble handed to each member, and of them successes.
    let handed_over: Vec<[AtomicUsize; 2]> =
        (0..card.members()).map(|_| Default::default()).collect();
    let (handover, start_gesture, start_routes) =
        (card.handover, card.start_gesture, card.start_routes);
    // Episodes each start route took to its member, and of them successes.
    let routed: Vec<[AtomicUsize; 2]> = start_routes.iter().map(|_| Default::default()).collect();
    if args.record_handovers.is_some() && handover.is_none() {
        bail!(
            "--record-handovers keeps where an ensemble hands an episode to its member, and {} \
             hands none over: make one that does with `dexcube handover`",
            prefix.display()
        );
    }
    if args.record_starts.is_some() && args.starts.is_some() && !args.after_gesture {
        bail!(
            "--record-starts with --starts would write the starts it replays again: drop one, \
             or add --after-gesture to record where a gesturing policy first acts after its \
             gesture"
        );
    }
    if args.after_gesture && start_gesture.is_none() {
        bail!(
            "--after-gesture records where the policy first acts after its start gesture, and \
             {} makes none: make one that does with `dexcube start-gesture`",
            prefix.display()
        );
    }
    let (starts, failure) = match &args.starts {
        None => (None, args.stage.recorded_failure()),
        Some(path) => {
            let (starts, failure) = starts_for(path, &scene, args.stage)?;
            (Some(starts), failure)
        }
    };
    let numbered = |starts: &Option<std::sync::Arc<[RecordedStart]>>| {
        starts.as_ref().map(|starts| StartMix {
            starts: starts.clone(),
            pick: StartPick::Numbered,
        })
    };
    let episodes = starts
        .as_ref()
        .map_or(args.episodes, |s| args.episodes.min(s.len()));
    // Starts from which the recorded policy failed, and this one did too.
    let recorded_failures = starts.as_ref().map_or(0, |s| {
        s[..episodes].iter().filter(|start| start.failed).count()
    });
    let failures_again = AtomicUsize::new(0);
    let rows = Mutex::new(Vec::new());
    let keep = Keep {
        start: args.record_starts.is_some(),
        after_gesture: args.after_gesture,
        closest: args.record_closest.is_some(),
        handover: args.record_handovers.is_some(),
        stray: args.record_strays.is_some().then_some(args.stray_radius),
    };
    let (recorded, recorded_closest) = (Mutex::new(Vec::new()), Mutex::new(Vec::new()));
    let (recorded_handovers, recorded_strays) = (Mutex::new(Vec::new()), Mutex::new(Vec::new()));
    // Episode k begins from recorded start k, or from a fresh placement seeded seed + k.
    let episode_seed = |k: usize| match starts {
        Some(_) => k as u64,
        None => args.seed + k as u64,
    };
    // Stage 2 turns a layer; Stage 1 poses the cube.
    let turning = args.stage == EnvKind::Layer;
    let bar = ProgressBar::new(episodes as u64);
    in_parallel(
        args.threads,
        episodes,
        || -> anyhow::Result<(Policy, Box<dyn SimulatedEnv>)> {
            let policy = Policy::load(&prefix, &burn::prelude::Device::flex())?;
            let env = setup.env(&policy, numbered(&starts))?;
            Ok((policy, env))
        },
        |(policy, env), k| {
            let trace = episode(
                env.as_mut(),
                policy,
                episode_seed(k),
                thresholds,
                keep,
                !turning,
                &mut |_| {},
            );
            let ending = Ending::of(&trace.info, thresholds, turning, trace.square);
            endings[ending as usize].fetch_add(1, Ordering::Relaxed);
            // What the recording counted as failing.
            let failed = match failure {
                RecordedFailure::Dropped => ending == Ending::Dropped,
                RecordedFailure::DroppedOrMissed => ending != Ending::Success,
                RecordedFailure::NotSquare => ending != Ending::Success || !trace.square,
            };
            if failed && starts.as_ref().is_some_and(|s| s[k].failed) {
                failures_again.fetch_add(1, Ordering::Relaxed);
            }
            if let Some(start) = trace.start {
                let start = RecordedStart { failed, ..start };
                recorded.lock().expect("no thread panics").push((k, start));
            }
            if let Some(closest) = trace.closest
                && !matches!(ending, Ending::Success | Ending::Dropped)
            {
                let closest = RecordedStart {
                    failed: true,
                    ..closest
                };
                let mut kept = recorded_closest.lock().expect("no thread panics");
                kept.push((k, closest));
            }
            for (state, kept) in [
                (trace.handover, &recorded_handovers),
                (trace.stray, &recorded_strays),
            ] {
                if let Some(state) = state {
                    let state = RecordedStart {
                        failed: ending != Ending::Success,
                        ..state
                    };
                    kept.lock().expect("no thread panics").push((k, state));
                }
            }
            if ending == Ending::Success && !trace.square {
                wins_out_of_square.fetch_add(1, Ordering::Relaxed);
            }
            if !turning && ending != Ending::Dropped && trace.turned_a_layer {
                layer_turns.fetch_add(1, Ordering::Relaxed);
                if ending == Ending::Success {
                    successes_with_layer_turns.fetch_add(1, Ordering::Relaxed);
                }
            }
            for [count, successes] in [
                trace.handed_to.map(|k| &handed_over[k]),
                trace.gestured.then_some(&gestured),
                trace.route.map(|k| &routed[k]),
            ]
            .into_iter()
            .flatten()
            {
                count.fetch_add(1, Ordering::Relaxed);
                if ending == Ending::Success {
                    successes.fetch_add(1, Ordering::Relaxed);
                }
            }
            if args.episodes_csv.is_some() {
                let first_at_goal = trace.first_at_goal.map_or(String::new(), |s| s.to_string());
                let mean_frame = trace
                    .mean_frame_angle_error
                    .map_or(String::new(), |e| format!("{e:.6}"));
                let row = format!(
                    "{k},{},{},{:.6},{:.6},{},{},{},{:.6},{first_at_goal},{mean_frame},{}",
                    episode_seed(k),
                    ending.tag(),
                    trace.info.position_error,
                    trace.info.angle_error,
                    trace.square,
                    trace.turned_a_layer,
                    trace.longest_hold,
                    trace.start_angle_error,
                    trace.handed_to.is_some(),
                );
                rows.lock().expect("no thread panics").push((k, row));
            }
            for (count, steps) in held.iter().zip(HOLDS) {
                if trace.longest_hold >= steps {
                    count.fetch_add(1, Ordering::Relaxed);
                }
            }
            bar.inc(1);
            Ok(())
        },
    )?;
    bar.finish_and_clear();
    if let Some(path) = &args.episodes_csv {
        let header = "episode,seed,ending,position_error,angle_error,square,turned_a_layer,\
                      longest_hold,start_angle_error,first_at_goal,mean_frame_angle_error,handed_over";
        let mut lines = vec![header.to_string()];
        lines.extend(in_episode_order(rows));
        let text = lines.join("\n") + "\n";
        write_atomically(path, text.as_bytes())
            .with_context(|| format!("writing the episodes' rows to {}", path.display()))?;
    }
    if let Some(path) = &args.video {
        let policy = Policy::load(&prefix, &burn::prelude::Device::flex())?;
        let mut env = setup.env(&policy, numbered(&starts))?;
        let mut video = Video::new(path, env.sim())?;
        let watch = &mut |sim: &mut Sim| video.watch(sim);
        episode(
            env.as_mut(),
            &policy,
            episode_seed(0),
            thresholds,
            Keep::default(),
            !turning,
            watch,
        );
        video.save()?;
    }
    let counts = endings.map(AtomicUsize::into_inner);
    let wins = counts[Ending::Success as usize];
    let (lo, hi) = wilson_interval(wins, episodes);
    let rate = wins as f64 / episodes as f64;
    let what = match args.stage {
        EnvKind::Rot => format!(
            "Stage 1 (CubeRotEnv, {} mode, {} cube)",
            files.rot_mode.name(),
            match object {
                ObjectKind::Cube => "physical",
                _ => "rigid",
            }
        ),
        EnvKind::Layer => format!(
            "Stage 2 (LayerOpEnv U' on the {}, goal +90°)",
            object.name()
        ),
    };
    let mut from = match &args.starts {
        Some(path) => format!("from the recorded starts in {}", path.display()),
        None => format!("seed {}", args.seed),
    };
    if control_rate != ControlRate::PAPER {
        from += &format!(
            ", acting every {control_rate} substeps ({} steps an episode)",
            control_rate.episode_steps()
        );
    }
    if args.physics_spread > 0.0 {
        from += &format!(", physics varied by spread {}", args.physics_spread);
    }
    if let Some(steps) = args.episode_steps {
        from += &format!(", {steps} steps an episode");
    }
    println!(
        "{what}: {wins}/{episodes} = {rate:.3} (95% CI {lo:.3} to {hi:.3}), {from}, policy {}",
        prefix.display()
    );
    for ending in Ending::ALL.into_iter().skip(1) {
        let n = counts[ending as usize];
        if n > 0 {
            println!("  {}: {n}", ending.name());
        }
    }
    let wins_out_of_square = wins_out_of_square.into_inner();
    if wins_out_of_square > 0 {
        println!(
            "  successes that left the cube out of its good state (a cubelet over 0.1 rad off): {wins_out_of_square}"
        );
    }
    if args.stage == EnvKind::Rot && object == ObjectKind::Cube {
        println!(
            "  kept the cube but ended with a layer turned from where it began: {} ({} of them successes)",
            layer_turns.into_inner(),
            successes_with_layer_turns.into_inner()
        );
    }
    if let Some(handover) = handover {
        let far = handover.far.map(|far| {
            (
                far.member,
                format!(" (stalled {} rad or more off)", far.beyond),
            )
        });
        for (member, which) in [(handover.member, String::new())].into_iter().chain(far) {
            let [count, successes] = &handed_over[member];
            println!(
                "  handed over to member {member}{which} in {} episodes ({} of them successes)",
                count.load(Ordering::Relaxed),
                successes.load(Ordering::Relaxed)
            );
        }
    }
    if start_gesture.is_some() {
        println!(
            "  began with the start gesture in {} episodes ({} of them successes)",
            gestured[0].load(Ordering::Relaxed),
            gestured[1].load(Ordering::Relaxed)
        );
    }
    for (route, [routes, successes]) in start_routes.iter().zip(&routed) {
        println!(
            "  routed to member {} in {} episodes ({} of them successes)",
            route.member,
            routes.load(Ordering::Relaxed),
            successes.load(Ordering::Relaxed)
        );
    }
    for (count, steps) in held.iter().zip(HOLDS) {
        println!(
            "  at the goal for {steps} step(s) running at some point: {}",
            count.load(Ordering::Relaxed)
        );
    }
    if starts.is_some() {
        println!(
            "  starts from which the recorded policy {}: {recorded_failures}; this one failed so from {} of them",
            failure.describe(),
            failures_again.into_inner()
        );
    }
    // Writes what the episodes recorded, in episode order, and returns it.
    let replayed = args.starts.as_ref().map_or(String::new(), |path| {
        format!(" --starts {}", path.display())
    });
    let save = |flag: &str, path: &Path, recorded: Mutex<Vec<(usize, RecordedStart)>>| {
        let starts = in_episode_order(recorded);
        let origin = StartsOrigin {
            stage: args.stage.name().to_string(),
            failure,
            scene: object.scene().name().to_string(),
            command: format!(
                "{}{replayed} {flag} {}",
                stage_command(&args, object, &prefix),
                path.display()
            ),
        };
        save_starts(path, &starts, &origin).map(|()| starts)
    };
    if let Some(path) = &args.record_starts {
        let flag = match args.after_gesture {
            true => "--after-gesture --record-starts",
            false => "--record-starts",
        };
        let starts = save(flag, path, recorded)?;
        let failed = starts.iter().filter(|s| s.failed).count();
        println!(
            "  recorded the {} starts (from {failed} of which this policy {}) in {}",
            starts.len(),
            failure.describe(),
            path.display()
        );
    }
    if let Some(path) = &args.record_closest {
        let closest = save("--record-closest", path, recorded_closest)?;
        println!(
            "  recorded where the {} misses that kept the cube came closest to their pose in {}",
            closest.len(),
            path.display()
        );
    }
    if let Some(path) = &args.record_handovers {
        let handovers = save("--record-handovers", path, recorded_handovers)?;
        let failed = handovers.iter().filter(|s| s.failed).count();
        println!(
            "  recorded where the {} episodes handed over ({failed} of them failed) were handed to the member in {}",
            handovers.len(),
            path.display()
        );
    }
    if let Some(path) = &args.record_strays {
        let flag = format!("--stray-radius {} --record-strays", args.stray_radius);
        let strays = save(&flag, path, recorded_strays)?;
        let failed = strays.iter().filter(|s| s.failed).count();
        println!(
            "  recorded where the {} episodes whose cube strayed more than {} m from its goal's position ({failed} of them failed) first did so in {}",
            strays.len(),
            args.stray_radius,
            path.display()
        );
    }
    if args.record {
        let wins = (wins, wins - wins_out_of_square);
        record(
            &prefix,
            &args,
            (object, object == setup.trained_object),
            wins,
            (lo, hi),
        )?;
    }
    Ok(ExitCode::SUCCESS)
}

/// Writes the result into the policy's card: as `evaluation` on the object it was trained on
/// (`own`), as `evaluation_on_<object>` on another, so both can stand side by side.
fn record(
    prefix: &Path,
    args: &EvalStageArgs,
    (object, own): (ObjectKind, bool),
    (successes, square_successes): (usize, usize),
    (lo, hi): (f64, f64),
) -> anyhow::Result<()> {
    let path = policy_file(prefix, "json");
    let mut card: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path)?)
        .with_context(|| format!("reading {}", path.display()))?;
    let key = if own {
        "evaluation".to_string()
    } else {
        format!("evaluation_on_{}", object.name())
    };
    card["metadata"][key] = serde_json::json!({
        "episodes": args.episodes,
        "successes": successes,
        "success_rate": successes as f64 / args.episodes as f64,
        "ci95": [lo, hi],
        "successes_left_square": square_successes,
        "seed": args.seed,
        "command": stage_command(args, object, prefix),
    });
    write_atomically(&path, serde_json::to_string_pretty(&card)?.as_bytes())?;
    Ok(())
}

/// The `eval-stage` command that runs these episodes of the policy at `prefix` on `object`.
fn stage_command(args: &EvalStageArgs, object: ObjectKind, prefix: &Path) -> String {
    format!(
        "dexcube eval-stage {stage} --object {} --episodes {} --seed {} --{stage}-policy {}",
        object.name(),
        args.episodes,
        args.seed,
        prefix.display(),
        stage = args.stage.name(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stage_2_misses_that_never_turned_the_layer_are_told_apart() {
        let miss = |angle_error: f64| Info {
            angle_error,
            ..Info::default()
        };
        let layer = (f64::INFINITY, 0.1);
        assert!(Ending::of(&miss(1.5), layer, true, true) == Ending::NeverTurned);
        assert!(Ending::of(&miss(1.5), layer, true, false) == Ending::Jammed);
        assert!(Ending::of(&miss(0.3), layer, true, false) == Ending::AngleOff);
        assert!(Ending::of(&miss(1.5), (0.01, 0.1), false, true) == Ending::AngleOff);
        let dropped = Info {
            dropped: true,
            ..miss(1.5)
        };
        assert!(Ending::of(&dropped, layer, true, false) == Ending::Dropped);
        let success = Info {
            is_success: true,
            ..Info::default()
        };
        assert!(Ending::of(&success, layer, true, true) == Ending::Success);
    }

    #[test]
    fn stage_1_mode_is_read_from_the_card_and_an_unknown_one_is_an_error() {
        let card = |environment: serde_json::Value| serde_json::json!({ "metadata": { "environment": environment } });
        let mode = |environment| rot_mode_of(&card(environment)).ok();
        assert_eq!(
            mode(serde_json::json!({ "variant": "pair" })),
            Some(RotMode::Pair)
        );
        // A run on the physical cube is named "pair-cube"; it used to be judged in paper mode.
        assert_eq!(
            mode(serde_json::json!({ "variant": "pair-cube" })),
            Some(RotMode::Pair)
        );
        assert_eq!(
            mode(serde_json::json!({ "variant": "pair-cube", "mode": "axis" })),
            Some(RotMode::Axis)
        );
        assert_eq!(mode(serde_json::json!({})), Some(RotMode::Paper));
        assert_eq!(mode(serde_json::json!({ "variant": "twirl" })), None);
    }

    /// The operator's flags as `eval` parses them.
    fn parse_operator(flags: &[&str]) -> Result<OperatorArgs, clap::Error> {
        #[derive(clap::Parser)]
        struct Cli {
            #[command(flatten)]
            operator: OperatorArgs,
        }
        let args = std::iter::once("eval").chain(flags.iter().copied());
        <Cli as clap::Parser>::try_parse_from(args).map(|cli| cli.operator)
    }

    /// The check after Stage 1 is on planning for the hand and off for the paper's operator,
    /// each unless told otherwise, and a run's record and command say which.
    #[test]
    fn the_puzzle_check_after_stage_1_is_the_hands_default_only() {
        let operator = |flags: &[&str]| parse_operator(flags).unwrap();
        for (flags, checked) in [
            (&[][..], true),
            (&["--no-stage1-puzzle-check"], false),
            (&["--paper-operator"], false),
            (&["--paper-operator", "--stage1-puzzle-check"], true),
            (
                &["--stage1-puzzle-check", "--no-stage1-puzzle-check"],
                false,
            ),
        ] {
            let args = operator(flags);
            assert_eq!(args.config(true).stage1_puzzle_check, checked, "{flags:?}");
            let named = args.name().contains("the puzzle checked after Stage 1");
            assert_eq!(named, checked, "{flags:?}: {}", args.name());
            assert_eq!(
                operator(&args.flags().split_whitespace().collect::<Vec<_>>())
                    .config(true)
                    .stage1_puzzle_check,
                checked,
                "{flags:?}: {}",
                args.flags()
            );
        }
        assert_eq!(operator(&["--paper-operator"]).name(), "paper");
    }

    /// Stage 1 run at another rate is part of the operator's name and flags, and is no
    /// longer the paper's operator.
    #[test]
    fn stage_1_at_another_control_rate_is_named_and_flagged() {
        let parse = parse_operator;
        let args = parse(&["--paper-operator", "--stage1-control-substeps", "10"]).unwrap();
        assert_eq!(
            args.config(true).driving.stage1_control_rate,
            ControlRate::every(10).ok()
        );
        assert!(args.name().ends_with(", Stage 1 acting every 10 substeps"));
        let again = parse(&args.flags().split_whitespace().collect::<Vec<_>>()).unwrap();
        assert_eq!(
            again.config(true).driving.stage1_control_rate,
            ControlRate::every(10).ok()
        );
        assert!(parse(&["--stage1-control-substeps", "3"]).is_err());
    }

    /// Stage 1's step budget is part of the operator's name and flags: 200 planning for the
    /// hand unless asked otherwise, none (the policy's episode) for the paper's operator.
    #[test]
    fn stage_1_s_step_budget_is_named_and_flagged() {
        let shipped = parse_operator(&[]).unwrap();
        assert_eq!(shipped.config(true).driving.stage1_steps, Some(200));
        assert!(shipped.name().contains(", Stage 1 up to 200 steps"));
        let args = parse_operator(&["--stage1-steps", "100"]).unwrap();
        assert_eq!(args.config(false).driving.stage1_steps, Some(100));
        assert!(args.name().contains(", Stage 1 up to 100 steps"));
        let again = parse_operator(&args.flags().split_whitespace().collect::<Vec<_>>()).unwrap();
        assert_eq!(again.config(false).driving.stage1_steps, Some(100));
        let paper = parse_operator(&["--paper-operator"]).unwrap();
        assert_eq!(paper.config(true).driving.stage1_steps, None);
        assert!(parse_operator(&["--stage1-steps", "0"]).is_err());
    }
}
