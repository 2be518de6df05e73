//! `dexcube distil`: one actor taught to act as a stage policy does (an ensemble above all) by
//! DAgger over the stage's own episodes, written as a single policy that can be evaluated, run
//! in the operator, or fine-tuned like any other.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;

use anyhow::bail;
use burn::prelude::Device;
use clap::Args;
use dexcube_env::{SimulatedEnv, StartMix, StartPick};
use dexcube_rl::Policy;
use dexcube_rl::checkpoint::write_atomically;
use dexcube_rl::distil::{Demonstrations, DistilConfig, fit};
use dexcube_rl::policy::policy_file;
use indicatif::{ProgressBar, ProgressStyle};

use crate::env::{EnvKind, starts_for};
use crate::eval::{PolicyArgs, in_parallel};
use crate::stage::{StageSetup, meets_paper_test};

#[derive(Args)]
pub struct DistilArgs {
    /// rot: Stage 1 (CubeRotEnv with the paper's three targets); layer: Stage 2 (LayerOpEnv U'
    /// with the goal exactly +90°): the episodes `eval-stage` runs, each on the object and at
    /// the rate the policy was trained at. The teacher is that stage's policy below, an
    /// ensemble typically; the student starts as its first member.
    #[arg(value_enum)]
    stage: EnvKind,
    #[command(flatten)]
    policies: PolicyArgs,
    /// Where to write the student (PATH.safetensors and PATH.json, rewritten after every
    /// round) and the rounds' figures (PATH-rounds.csv).
    #[arg(long)]
    out: PathBuf,
    /// DAgger rounds: the teacher acts in the first round's episodes, the student in every
    /// later round's; the teacher labels every state of them all.
    #[arg(long, default_value_t = 4)]
    rounds: usize,
    /// Episodes per round, each of the stage's full length.
    #[arg(long, default_value_t = 250)]
    episodes: usize,
    /// Passes over all the labels gathered so far, after each round.
    #[arg(long, default_value_t = DistilConfig::default().epochs)]
    epochs: usize,
    /// Also begin episodes from these recorded starts (made by `eval --record-starts` for rot,
    /// `eval --record-layer-starts` for layer): where the operator hands the stage the cube,
    /// which fresh placements do not reach. Each episode begins from one with probability
    /// --start-share, drawn alike.
    #[arg(long, value_name = "FILE")]
    starts: Option<PathBuf>,
    /// The share of episodes that begin from --starts.
    #[arg(long, default_value_t = 0.5, requires = "starts", value_parser = share)]
    start_share: f64,
    /// Episode k of round r is reset with seed seed + r * episodes + k (a fresh placement, or a
    /// recorded start drawn by that seed); round r's fit shuffles with seed + r. The default
    /// is a range no evaluation uses.
    #[arg(long, default_value_t = 5_000_000)]
    seed: u64,
    #[arg(long, default_value_t = 2)]
    threads: usize,
}

/// A share of episodes: a number from 0 to 1.
fn share(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if (0.0..=1.0).contains(&x) => Ok(x),
        _ => Err(format!("a share is a number from 0 to 1, not '{text}'")),
    }
}

/// What one round gathered and fitted.
#[derive(serde::Serialize)]
struct Round {
    round: usize,
    /// Who acted in its episodes.
    acting: &'static str,
    episodes: usize,
    /// Episodes that ended meeting the paper's test: a deterministic evaluation of whoever
    /// acted, on fresh placements.
    successes: usize,
    /// The labels gathered so far.
    rows: usize,
    /// The student's mean squared difference from the teacher's actions over them, before and
    /// after the round's fit.
    error_before_fit: f64,
    error_after_fit: f64,
}

pub fn run(args: DistilArgs) -> anyhow::Result<ExitCode> {
    if args.rounds == 0 || args.episodes == 0 || args.epochs == 0 {
        bail!("--rounds, --episodes and --epochs must each be at least 1");
    }
    let files = args.policies.files()?;
    let setup = StageSetup::new(args.stage, &files, None, None)?;
    let same_file = |a: &std::path::Path, b: &std::path::Path| {
        let card = |p: &std::path::Path| policy_file(p, "json").canonicalize().ok();
        a == b || card(a).is_some_and(|a| Some(a) == card(b))
    };
    if same_file(&args.out, &setup.prefix) {
        bail!(
            "--out {} is the teacher itself, which the rounds read again: write the student \
             elsewhere",
            args.out.display()
        );
    }
    let teacher = Policy::load(&setup.prefix, &Device::flex())?;
    if teacher.card.goal_lead.is_some() {
        bail!(
            "{} is shown its goal led on, which a student shown the goal itself cannot learn \
             from its actions: distil the policy it was made from (its card's metadata.led \
             names it)",
            setup.prefix.display()
        );
    }
    if teacher.card.nearest_frame {
        bail!(
            "{} is shown the cube in the frame nearest its goal, which the student, labelled \
             by its members' actions step by step, would not be: distil the policy it was made \
             from (its card's metadata.nearest_frame names it)",
            setup.prefix.display()
        );
    }
    if teacher.card.handover.is_some() {
        bail!(
            "{} hands stalled episodes to a member, which a student labelled step by step \
             cannot learn from its actions: distil the ensemble it was made from (its card's \
             metadata.handing_over names it)",
            setup.prefix.display()
        );
    }
    if !teacher.card.start_routes.is_empty() {
        bail!(
            "{} hands some episodes to one member by where the cube starts, which a student \
             labelled step by step cannot learn from its actions: distil the ensemble it was \
             made from (its card's metadata.start_route names it)",
            setup.prefix.display()
        );
    }
    if teacher.card.start_gesture.is_some() {
        bail!(
            "{} makes a start gesture before it first acts, which a student labelled step by \
             step cannot learn from its actions: distil the policy it was made from (its card's \
             metadata.start_gesture names it)",
            setup.prefix.display()
        );
    }
    let starts = match &args.starts {
        None => None,
        Some(path) => Some(StartMix {
            starts: starts_for(path, &setup.scene, args.stage)?.0,
            pick: StartPick::Share {
                share: args.start_share,
                failed_weight: 1.0,
            },
        }),
    };
    let mut command = format!(
        "dexcube distil {stage} --{stage}-policy {} --out {} --rounds {} --episodes {} \
         --epochs {} --seed {}",
        setup.prefix.display(),
        args.out.display(),
        args.rounds,
        args.episodes,
        args.epochs,
        args.seed,
        stage = args.stage.name(),
    );
    if let Some(path) = &args.starts {
        command += &format!(
            " --starts {} --start-share {}",
            path.display(),
            args.start_share
        );
    }
    let head = &teacher.card.metadata;
    let label = head["label"].as_str().unwrap_or("an unlabelled policy");
    let metadata = |rounds: &[Round]| {
        serde_json::json!({
            "label": format!("distilled from {label}"),
            "environment": head["environment"],
            "distilled_from": setup.prefix,
            "starts": args.starts,
            "start_share": args.starts.as_ref().map(|_| args.start_share),
            "teacher_members": head.get("ensemble"),
            "command": command,
            "distillation": {
                "method": "DAgger (Ross et al. 2011): the teacher acts in round 0, the student after; \
                           the teacher labels every state",
                "epochs": args.epochs,
                "rounds": rounds,
            },
        })
    };
    let config = DistilConfig {
        epochs: args.epochs,
        ..DistilConfig::default()
    };
    let mut student = teacher.first_member(metadata(&[]));
    student.write(&args.out)?;
    let bar = ProgressBar::new((args.rounds * args.episodes) as u64).with_style(
        ProgressStyle::with_template(
            "[{elapsed_precise}] {wide_bar} {pos}/{len} episodes, ETA {eta} {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut demonstrations = Demonstrations::default();
    let mut rounds: Vec<Round> = Vec::with_capacity(args.rounds);
    for round in 0..args.rounds {
        let teacher_acts = round == 0;
        bar.set_message(format!("round {round}"));
        let first_seed = args.seed + (round * args.episodes) as u64;
        let gathered = Mutex::new(Vec::with_capacity(args.episodes));
        in_parallel(
            args.threads,
            args.episodes,
            || -> anyhow::Result<(Policy, Policy, Box<dyn SimulatedEnv>)> {
                let device = Device::flex();
                let teacher = Policy::load(&setup.prefix, &device)?;
                let student = Policy::load(&args.out, &device)?;
                let env = setup.env(&teacher, starts.clone())?;
                Ok((teacher, student, env))
            },
            |(teacher, student, env), k| {
                let (shown, success) = demonstrate(
                    env.as_mut(),
                    (teacher, student),
                    teacher_acts,
                    first_seed + k as u64,
                    setup.thresholds,
                );
                gathered
                    .lock()
                    .expect("no thread panics")
                    .push((k, shown, success));
                bar.inc(1);
                Ok(())
            },
        )?;
        let mut gathered = gathered.into_inner().expect("no thread panics");
        gathered.sort_by_key(|(k, _, _)| *k);
        let successes = gathered.iter().filter(|(_, _, success)| *success).count();
        gathered
            .into_iter()
            .for_each(|(_, shown, _)| demonstrations.extend(shown));
        let error_before_fit = demonstrations.mean_squared_error(&student);
        student = fit(&student, &demonstrations, config, args.seed + round as u64)?;
        rounds.push(Round {
            round,
            acting: if teacher_acts { "teacher" } else { "student" },
            episodes: args.episodes,
            successes,
            rows: demonstrations.rows(),
            error_before_fit,
            error_after_fit: demonstrations.mean_squared_error(&student),
        });
        let last = &rounds[round];
        bar.println(format!(
            "round {round}: the {} succeeded in {successes}/{} episodes; {} labels; the \
             student's error {:.5} -> {:.5}",
            last.acting, args.episodes, last.rows, last.error_before_fit, last.error_after_fit
        ));
        student.card.metadata = metadata(&rounds);
        student.write(&args.out)?;
        write_rounds(&args.out, &rounds)?;
    }
    bar.finish_and_clear();
    println!(
        "wrote the student to {}; score it with `dexcube eval-stage {stage} --{stage}-policy {}`",
        args.out.display(),
        args.out.display(),
        stage = args.stage.name(),
    );
    Ok(ExitCode::SUCCESS)
}

/// One episode from `seed`, acted by the teacher or the student, with the teacher's action
/// at every state; and whether it ended meeting the paper's test.
fn demonstrate(
    env: &mut dyn SimulatedEnv,
    (teacher, student): (&Policy, &Policy),
    teacher_acts: bool,
    seed: u64,
    thresholds: (f64, f64),
) -> (Demonstrations, bool) {
    let (mut obs, _) = env.reset(Some(seed));
    let mut shown = Demonstrations::default();
    loop {
        let taught = shown.label(teacher, student, &obs.observation, &obs.desired_goal);
        let action = if teacher_acts {
            taught
        } else {
            student.act(&obs.observation, &obs.desired_goal)
        };
        let t = env.step(&action);
        if t.terminated || t.truncated {
            return (shown, meets_paper_test(&t.info, thresholds));
        }
        obs = t.observation;
    }
}

/// The rounds so far as `PREFIX-rounds.csv`, written atomically.
fn write_rounds(out: &std::path::Path, rounds: &[Round]) -> anyhow::Result<()> {
    let mut csv =
        String::from("round,acting,episodes,successes,rows,error_before_fit,error_after_fit\n");
    for r in rounds {
        csv += &format!(
            "{},{},{},{},{},{},{}\n",
            r.round,
            r.acting,
            r.episodes,
            r.successes,
            r.rows,
            r.error_before_fit,
            r.error_after_fit
        );
    }
    let name = format!(
        "{}-rounds.csv",
        out.file_name().unwrap_or_default().to_string_lossy()
    );
    write_atomically(&out.with_file_name(name), csv.as_bytes())?;
    Ok(())
}
