//! The training loop, HER baselines' schedule: an epoch is `cycles_per_epoch` cycles; a cycle
//! collects one exploring episode from every environment, feeds the normalisers and the
//! replay buffer, runs `batches_per_cycle` optimisation steps and updates the targets; each
//! epoch ends with deterministic test episodes. After every epoch it writes, atomically:
//!
//! - `checkpoint/`: all four networks (six with TD3's twin critics), each optimiser's moments
//!   (`optimizer-*.bpk`) and `state.json` (config, normalisers, progress, the learner's step
//!   count and noise stream, and the replay buffer's position), from which `resume`
//!   continues exactly as an uninterrupted run would, with how the run began (its warm start
//!   and critic-only epochs, which only its first call names). It is written whole into
//!   `checkpoint.tmp/` and then swapped in, so a run killed at any moment leaves the last
//!   complete one. The same checkpoint can also warm-start a new run (`init_from`) on a
//!   changed goal or success test: networks and normalisers carry over, everything else
//!   starts afresh.
//! - `replay/epoch-NNNN.bin`: each epoch's episodes, exactly, as long as the replay buffer
//!   still holds any of them; a resume refills the buffer from them.
//! - `best.safetensors` + `best.json`: the policy with the highest test success so far.
//! - `policy.safetensors` + `policy.json`: the latest policy.
//! - `snapshots/epoch-NNNN.safetensors` + `.json`: the policy every `snapshot_every` epochs.
//!   DDPG can collapse suddenly, and the best epoch by a dozen test episodes is a noisy pick:
//!   snapshots keep the candidates for a proper evaluation (`dexcube eval-stage`).
//! - `metrics.csv` and `success.png`: the learning curve.
//!
//! Every random choice comes from the seed: environment `i` of the `k`-th batch of episodes
//! is reset with a seed derived from (seed, k, i), and exploration noise from (seed, epoch).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use burn::prelude::*;
use dexcube_env::{GoalEnv, VecEnv};
use indicatif::{ProgressBar, ProgressStyle};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::agent::{Agent, Dims, LearnerState, Learners, SavedAnchor, StepStats};
use crate::checkpoint::{self, CheckpointError};
use crate::config::DdpgHerConfig;
use crate::normalizer::Normalizer;
use crate::plot::{Series, line_plot};
use crate::policy::Policy;
use crate::replay::{EpisodeFile, HerBuffer, ReplayPosition, episodes_from_bytes};
use crate::rollout::rollout;

pub struct TrainOptions {
    pub epochs: usize,
    /// Environments stepped together; each gives one episode per cycle.
    pub envs: usize,
    /// Threads stepping the environments.
    pub threads: usize,
    pub seed: u64,
    /// Where checkpoints, policies and curves go; `None` keeps everything in memory.
    pub out_dir: Option<PathBuf>,
    /// Continue from `out_dir/checkpoint` if it exists.
    pub resume: bool,
    /// Warm start: take the networks and normalisers of the run in this folder (its
    /// `checkpoint/`), then train as a new run. Only the sizes must match.
    pub init_from: Option<PathBuf>,
    /// Take the actor (and its target) and the normalisers from this policy
    /// (`PREFIX.safetensors` and `PREFIX.json`, e.g. a shipped one, which may be an earlier
    /// epoch than a run's last checkpoint). With `init_from` the critic comes from that run;
    /// without, it starts afresh, and `critic_only_epochs` should give it time to learn the
    /// policy's values first.
    pub init_actor: Option<PathBuf>,
    /// Keep the policy of every this many epochs under `snapshots/` (0: none).
    pub snapshot_every: usize,
    /// The run's first epochs in which only the critic learns ([`Learners::CriticOnly`]):
    /// after a warm start onto another object or success test, the replay buffer and the
    /// optimisers' moments start empty, and an actor steered at once by a critic fitted to
    /// a few episodes can lose what it knew (0: none, DDPG as published). A resumed run keeps
    /// the number its first call gave.
    pub critic_only_epochs: usize,
    /// Start the actor (and its target) with a zero output layer, so that it first acts with
    /// zero: a residual's start, which acts as its base ([`crate::residual`]). A fresh run's
    /// only: a warm start brings an actor of its own.
    pub zero_output: bool,
    /// Stop before `epochs` once this rule is met (a recipe's phase that has done its work).
    pub until: Option<Until>,
    /// Called with every epoch's metrics so far once its checkpoint is written (a recipe
    /// keeps its whole curve up to date).
    pub after_epoch: Option<Arc<EpochHook>>,
    /// Show a progress bar with ETA on stderr.
    pub progress: bool,
    /// What is being trained, for plots and policy cards.
    pub label: String,
    /// Facts about the environment, recorded in policy cards.
    pub metadata: serde_json::Value,
}

impl TrainOptions {
    /// A fresh run of `epochs` kept in memory: no warm start, resume, snapshots, progress bar
    /// or metadata. What tests and benchmarks train with; set `out_dir` and the rest on top.
    pub fn in_memory(label: &str, epochs: usize, envs: usize, threads: usize, seed: u64) -> Self {
        TrainOptions {
            epochs,
            envs,
            threads,
            seed,
            out_dir: None,
            resume: false,
            init_from: None,
            init_actor: None,
            snapshot_every: 0,
            critic_only_epochs: 0,
            zero_output: false,
            until: None,
            after_epoch: None,
            progress: false,
            label: label.into(),
            metadata: serde_json::json!({}),
        }
    }
}

/// What [`TrainOptions::after_epoch`] calls.
pub type EpochHook = dyn Fn(&[EpochMetrics]) -> Result<(), TrainError> + Send + Sync;

/// When a run has done its work before its last epoch: once the mean test success of its
/// last `window` epochs reaches `success`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Until {
    pub success: f64,
    pub window: usize,
}

impl Until {
    /// Whether a run with these epochs has met the rule.
    pub fn met(&self, metrics: &[EpochMetrics]) -> bool {
        let window = self.window.max(1);
        metrics.len() >= window
            && metrics[metrics.len() - window..]
                .iter()
                .map(|m| m.test_success)
                .sum::<f64>()
                / window as f64
                >= self.success
    }
}

/// One epoch's record, a row of `metrics.csv`.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct EpochMetrics {
    pub epoch: usize,
    pub episodes: usize,
    pub env_steps: usize,
    pub updates: usize,
    pub test_success: f64,
    pub train_success: f64,
    pub mean_q: f64,
    pub critic_loss: f64,
    pub actor_loss: f64,
    /// Environment steps per second over the epoch's wall time.
    pub env_steps_per_s: f64,
    /// Seconds of the epoch spent collecting episodes (physics and acting), learning
    /// (sampling and optimisation), and the rest.
    pub rollout_s: f64,
    pub learning_s: f64,
    pub other_s: f64,
    /// Seconds since training began, resumed runs included.
    pub wall_s: f64,
}

const CSV_HEADER: &str = "epoch,episodes,env_steps,updates,test_success,train_success,mean_q,critic_loss,actor_loss,env_steps_per_s,rollout_s,learning_s,other_s,wall_s";

impl EpochMetrics {
    fn csv_row(&self) -> String {
        format!(
            "{},{},{},{},{:.4},{:.4},{:.4},{:.6},{:.6},{:.1},{:.2},{:.2},{:.2},{:.1}",
            self.epoch,
            self.episodes,
            self.env_steps,
            self.updates,
            self.test_success,
            self.train_success,
            self.mean_q,
            self.critic_loss,
            self.actor_loss,
            self.env_steps_per_s,
            self.rollout_s,
            self.learning_s,
            self.other_s,
            self.wall_s
        )
    }
}

/// Everything needed to continue training, beside the networks.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct TrainState {
    label: String,
    seed: u64,
    dims: Dims,
    config: DdpgHerConfig,
    observation_norm: Normalizer,
    goal_norm: Normalizer,
    metrics: Vec<EpochMetrics>,
    /// How the run began, kept so that a resumed run keeps it.
    #[serde(default)]
    start: Option<RunStart>,
    /// Older checkpoints kept only the run this one was warm-started from; their resumes take
    /// the rest of [`RunStart`] from the resuming call.
    #[serde(default, skip_serializing)]
    init_from: Option<PathBuf>,
    /// The anchor's normalisers (observation, goal), for a run fine-tuned with one; its
    /// weights are `checkpoint/anchor.safetensors`.
    #[serde(default)]
    anchor_normalizers: Option<[Normalizer; 2]>,
    /// The learner's step count, noise stream and the ids its optimisers' moments
    /// (`optimizer-*.bpk`) are keyed by; older checkpoints kept none.
    #[serde(default)]
    learner: Option<LearnerState>,
    /// The replay buffer's position and the epochs' episode files that refill it; older
    /// checkpoints kept none.
    #[serde(default)]
    replay: Option<ReplayLog>,
}

/// The replay buffer as a checkpoint finds it again: where it stood, and the files of the
/// epochs whose episodes it still held (`replay/epoch-NNNN.bin`), oldest first.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct ReplayLog {
    position: ReplayPosition,
    segments: Vec<Segment>,
}

/// One epoch's episodes on disk: the number (counted over the buffer's life) of the first of
/// them the buffer stored, and how many it stored.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
struct Segment {
    epoch: usize,
    first: usize,
    stored: usize,
}

impl Segment {
    fn path(dir: &Path, epoch: usize) -> PathBuf {
        dir.join("replay").join(format!("epoch-{epoch:04}.bin"))
    }
}

impl ReplayLog {
    /// The log after an epoch that added `segment`: the segments whose episodes the buffer
    /// at `position` still holds.
    fn after(&self, segment: Segment, position: ReplayPosition) -> ReplayLog {
        let oldest = position.stored - position.held;
        let segments = self
            .segments
            .iter()
            .copied()
            .chain(std::iter::once(segment))
            .filter(|s| s.first + s.stored > oldest)
            .collect();
        ReplayLog { position, segments }
    }
}

/// What a run's first call set that its resumes keep, since only that call is given them: the
/// run it was warm-started from, the card's environment facts (which name a policy the actor
/// came from) and the critic-only epochs.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct RunStart {
    init_from: Option<PathBuf>,
    environment: serde_json::Value,
    critic_only_epochs: usize,
}

impl RunStart {
    fn of(options: &TrainOptions) -> Self {
        RunStart {
            init_from: options.init_from.clone(),
            environment: options.metadata.clone(),
            critic_only_epochs: options.critic_only_epochs,
        }
    }
}

#[derive(Debug)]
pub enum TrainError {
    Checkpoint(CheckpointError),
    Resume(String),
    WarmStart(String),
    Plot(String),
    Recipe(String),
}

impl std::fmt::Display for TrainError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TrainError::Checkpoint(e) => e.fmt(f),
            TrainError::Resume(message) => write!(f, "cannot resume: {message}"),
            TrainError::WarmStart(message) => write!(f, "cannot warm-start: {message}"),
            TrainError::Plot(message) => write!(f, "cannot draw the learning curve: {message}"),
            TrainError::Recipe(message) => write!(f, "cannot run the recipe: {message}"),
        }
    }
}

impl std::error::Error for TrainError {}

impl From<CheckpointError> for TrainError {
    fn from(e: CheckpointError) -> Self {
        TrainError::Checkpoint(e)
    }
}

/// The outcome: every epoch's metrics (resumed ones included) and the trained agent.
pub struct Trained {
    pub metrics: Vec<EpochMetrics>,
    pub agent: Agent,
}

const NETWORK_FILES: [&str; 4] = ["actor", "critic", "target_actor", "target_critic"];

/// TD3's second critic and its target, in a checkpoint of a run with twin critics.
const TWIN_FILES: [&str; 2] = ["critic2", "target_critic2"];

/// The anchor's weights in a checkpoint, for a run fine-tuned with one.
const ANCHOR_FILE: &str = "anchor.safetensors";

/// The optimisers' moments in a checkpoint, in the order of [`LearnerState::parameter_ids`].
const OPTIMIZER_FILES: [&str; 3] = [
    "optimizer-actor.bpk",
    "optimizer-critic.bpk",
    "optimizer-critic2.bpk",
];

/// Where a checkpoint is written before it is swapped in, and where the one it replaces waits
/// meanwhile.
const CHECKPOINT_NEW: &str = "checkpoint.tmp";
const CHECKPOINT_OLD: &str = "checkpoint.old";

/// The critics in the checkpoint of a training run (the first, and TD3's second where the run
/// had one), with what they read their inputs through: what a guide takes from a run.
pub(crate) struct RunCritics {
    pub dims: Dims,
    pub hidden: Vec<usize>,
    pub observation_norm: Normalizer,
    pub goal_norm: Normalizer,
    pub critics: Vec<Vec<crate::params::NamedTensor>>,
}

/// Reads the critics of the run in `dir`.
pub(crate) fn read_critics(dir: &Path) -> Result<RunCritics, CheckpointError> {
    let checkpoint_dir = dir.join("checkpoint");
    let state_path = checkpoint_dir.join("state.json");
    if !state_path.exists() {
        return Err(CheckpointError::Mismatch {
            path: dir.to_path_buf(),
            message: "it is not a training run's folder (it has no checkpoint/state.json): \
                      pass the folder `dexcube train --out` wrote"
                .to_string(),
        });
    }
    let state: TrainState = checkpoint::load_json(&state_path)?;
    let file = |name: &str| checkpoint_dir.join(format!("{name}.safetensors"));
    let mut critics = vec![checkpoint::load_tensors(&file(NETWORK_FILES[1]))?];
    if file(TWIN_FILES[0]).exists() {
        critics.push(checkpoint::load_tensors(&file(TWIN_FILES[0]))?);
    }
    Ok(RunCritics {
        dims: state.dims,
        hidden: state.config.hidden,
        observation_norm: state.observation_norm,
        goal_norm: state.goal_norm,
        critics,
    })
}

/// A seed for the `batch`-th batch of episodes, distinct for training and testing.
fn episode_seed(seed: u64, batch: u64, test: bool) -> u64 {
    seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (batch << 20) ^ ((test as u64) << 62)
}

/// Trains DDPG + HER on environments made by `make_env`.
pub fn train<E: GoalEnv>(
    make_env: impl Fn() -> E,
    config: DdpgHerConfig,
    options: &TrainOptions,
) -> Result<Trained, TrainError> {
    let probe = make_env();
    let spaces = probe.spaces();
    let goal = probe.goal();
    drop(probe);
    let dims = Dims {
        observation: spaces.observation,
        goal: spaces.goal,
        action: spaces.action,
    };
    let mut envs = VecEnv::new(
        (0..options.envs).map(|_| make_env()).collect(),
        options.threads,
    );
    let mut agent = Agent::new(dims, config.clone(), &Device::flex(), options.seed);
    let mut buffer = HerBuffer::new(dims, config.buffer_size, config.future_probability(), goal);
    let resumed = match (options.resume, &options.out_dir) {
        (true, Some(dir)) => resume(&mut agent, &mut buffer, dir, options)?,
        _ => None,
    };
    let (mut metrics, start, mut replay) =
        resumed.unwrap_or_else(|| (Vec::new(), RunStart::of(options), ReplayLog::default()));
    if metrics.is_empty() {
        let warm = options.init_from.is_some() || options.init_actor.is_some();
        if options.zero_output && warm {
            return Err(TrainError::WarmStart(
                "a zero output starts a fresh actor, and a warm start brings one: leave out one \
                 or the other"
                    .into(),
            ));
        }
        match (&options.init_from, &options.init_actor) {
            (Some(dir), actor_from) => warm_start(&mut agent, dir, actor_from.as_deref())?,
            (None, Some(prefix)) => warm_start_actor(&mut agent, prefix)?,
            (None, None) if config.anchor > 0.0 => {
                return Err(TrainError::WarmStart(
                    "an anchor holds the actor near the one it starts from, so it needs a \
                     warm start (a run or a policy to start from)"
                        .into(),
                ));
            }
            (None, None) => {}
        }
        if options.zero_output {
            agent.zero_output();
        }
        if config.anchor > 0.0 {
            agent.set_anchor_here();
        }
    }
    let cycles = config.cycles_per_epoch as u64;
    let updates_per_epoch = (config.cycles_per_epoch * config.batches_per_cycle) as f64;
    let bar = progress_bar(options, config.cycles_per_epoch, metrics.len());
    let wall_before = metrics.last().map_or(0.0, |m| m.wall_s);
    let started = Instant::now();
    let mut best = metrics
        .iter()
        .map(|m| m.test_success)
        .fold(f64::NEG_INFINITY, f64::max);
    let done = |metrics: &[EpochMetrics]| options.until.is_some_and(|rule| rule.met(metrics));
    for epoch in metrics.len()..options.epochs {
        if done(&metrics) {
            break;
        }
        let epoch_start = Instant::now();
        let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
        rng.set_stream(epoch as u64);
        let (mut rollout_s, mut learning_s) = (0.0, 0.0);
        let (mut train_successes, mut train_episodes, mut steps) = (0, 0, 0);
        let mut stats = StepStats::default();
        let learners = if epoch < start.critic_only_epochs {
            Learners::CriticOnly
        } else {
            Learners::ActorAndCritic
        };
        let first_stored = buffer.position().stored;
        let mut epoch_episodes = EpisodeFile::new(dims);
        for cycle in 0..cycles {
            let t = Instant::now();
            let (episodes, s) = rollout(
                &mut envs,
                &agent,
                episode_seed(options.seed, epoch as u64 * cycles + cycle, false),
                Some(&mut rng),
            );
            rollout_s += t.elapsed().as_secs_f64();
            let t = Instant::now();
            (train_successes, train_episodes, steps) = (
                train_successes + s.successes,
                train_episodes + s.episodes,
                steps + s.steps,
            );
            for episode in episodes {
                for (o, g) in buffer.normalizer_rows(&episode, episode.len, &mut rng) {
                    agent.observation_norm.update(o);
                    agent.goal_norm.update(g);
                }
                if options.out_dir.is_some() {
                    epoch_episodes.push(&episode);
                }
                buffer.store(episode);
            }
            for _ in 0..config.batches_per_cycle {
                let batch = buffer.sample(config.batch_size, &mut rng);
                let s = agent.train(&batch, learners);
                stats.critic_loss += s.critic_loss / updates_per_epoch;
                stats.actor_loss += s.actor_loss / updates_per_epoch;
                stats.mean_q += s.mean_q / updates_per_epoch;
            }
            agent.end_cycle();
            learning_s += t.elapsed().as_secs_f64();
            bar.inc(1);
        }
        let t = Instant::now();
        let test_batches = config.test_episodes.div_ceil(options.envs).max(1) as u64;
        let (mut test_successes, mut test_episodes) = (0, 0);
        for k in 0..test_batches {
            let (_, s) = rollout(
                &mut envs,
                &agent,
                episode_seed(options.seed, epoch as u64 * test_batches + k, true),
                None,
            );
            (test_successes, test_episodes) =
                (test_successes + s.successes, test_episodes + s.episodes);
        }
        rollout_s += t.elapsed().as_secs_f64();
        let previous = metrics.last();
        let epoch_s = epoch_start.elapsed().as_secs_f64();
        let row = EpochMetrics {
            epoch,
            episodes: previous.map_or(0, |m| m.episodes) + train_episodes,
            env_steps: previous.map_or(0, |m| m.env_steps) + steps,
            updates: previous.map_or(0, |m| m.updates) + cycles as usize * config.batches_per_cycle,
            test_success: test_successes as f64 / test_episodes as f64,
            train_success: train_successes as f64 / train_episodes.max(1) as f64,
            mean_q: stats.mean_q,
            critic_loss: stats.critic_loss,
            actor_loss: stats.actor_loss,
            env_steps_per_s: steps as f64 / epoch_s,
            rollout_s,
            learning_s,
            other_s: (epoch_s - rollout_s - learning_s).max(0.0),
            wall_s: wall_before + started.elapsed().as_secs_f64(),
        };
        bar.set_message(format!("test success {:.2}", row.test_success));
        if options.progress && bar.is_hidden() {
            // No terminal to draw a bar on (a log file): one line per epoch instead.
            eprintln!(
                "{} epoch {}/{}: test success {:.2}, train success {:.2}, {} episodes, {:.0} s",
                options.label,
                epoch + 1,
                options.epochs,
                row.test_success,
                row.train_success,
                row.episodes,
                row.wall_s
            );
        }
        let improved = row.test_success > best;
        best = best.max(row.test_success);
        metrics.push(row);
        if let Some(dir) = &options.out_dir {
            let position = buffer.position();
            let segment = Segment {
                epoch,
                first: first_stored,
                stored: position.stored - first_stored,
            };
            let bytes = epoch_episodes.into_bytes();
            checkpoint::write_atomically(&Segment::path(dir, epoch), &bytes)?;
            replay = replay.after(segment, position);
            let run = SavedRun {
                agent: &agent,
                start: &start,
                metrics: &metrics,
                replay: &replay,
            };
            save_epoch(run, dir, options, improved)?;
        }
        if let Some(hook) = &options.after_epoch {
            hook(&metrics)?;
        }
    }
    bar.finish();
    Ok(Trained { metrics, agent })
}

fn progress_bar(options: &TrainOptions, cycles: usize, done_epochs: usize) -> ProgressBar {
    if !options.progress {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new((options.epochs * cycles) as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{prefix} [{elapsed_precise}] {wide_bar} epoch {pos}/{len} cycles, ETA {eta} {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_prefix(options.label.clone());
    bar.set_position((done_epochs * cycles) as u64);
    bar
}

fn card_metadata(
    options: &TrainOptions,
    start: &RunStart,
    metrics: &[EpochMetrics],
) -> serde_json::Value {
    let last = metrics.last();
    serde_json::json!({
        "label": options.label,
        "environment": start.environment,
        "seed": options.seed,
        "envs": options.envs,
        "epochs": metrics.len(),
        "episodes": last.map_or(0, |m| m.episodes),
        "env_steps": last.map_or(0, |m| m.env_steps),
        "updates": last.map_or(0, |m| m.updates),
        "wall_s": last.map_or(0.0, |m| m.wall_s),
        "test_success": last.map_or(0.0, |m| m.test_success),
        "init_from": start.init_from.as_ref().map(|d| d.display().to_string()),
    })
}

/// What an epoch's checkpoint saves of the run.
struct SavedRun<'a> {
    agent: &'a Agent,
    start: &'a RunStart,
    metrics: &'a [EpochMetrics],
    replay: &'a ReplayLog,
}

fn save_epoch(
    run: SavedRun,
    dir: &Path,
    options: &TrainOptions,
    improved: bool,
) -> Result<(), TrainError> {
    let SavedRun {
        agent,
        start,
        metrics,
        replay,
    } = run;
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |e: std::io::Error| CheckpointError::Io {
            path,
            message: e.to_string(),
        }
    };
    let checkpoint_dir = dir.join(CHECKPOINT_NEW);
    if checkpoint_dir.exists() {
        std::fs::remove_dir_all(&checkpoint_dir).map_err(io(&checkpoint_dir))?;
    }
    let twin = agent
        .twin_networks()
        .into_iter()
        .flat_map(|n| TWIN_FILES.iter().zip(n));
    for (name, tensors) in NETWORK_FILES.iter().zip(agent.networks()).chain(twin) {
        checkpoint::save_tensors(
            &checkpoint_dir.join(format!("{name}.safetensors")),
            &tensors,
        )?;
    }
    let anchor = agent.anchor();
    if let Some(anchor) = &anchor {
        checkpoint::save_tensors(&checkpoint_dir.join(ANCHOR_FILE), &anchor.actor)?;
    }
    let (learner, records) = agent.learner_state();
    for (record, name) in records.into_iter().zip(OPTIMIZER_FILES) {
        let path = checkpoint_dir.join(name);
        record.save(&path).map_err(|e| CheckpointError::Io {
            path: path.clone(),
            message: e.to_string(),
        })?;
    }
    let state = TrainState {
        label: options.label.clone(),
        seed: options.seed,
        dims: agent.dims,
        config: agent.config.clone(),
        observation_norm: agent.observation_norm.clone(),
        goal_norm: agent.goal_norm.clone(),
        metrics: metrics.to_vec(),
        start: Some(start.clone()),
        init_from: None,
        anchor_normalizers: anchor.map(|anchor| [anchor.observation_norm, anchor.goal_norm]),
        learner: Some(learner),
        replay: Some(replay.clone()),
    };
    // The state goes last: a checkpoint is complete once state.json names its epoch. Then it
    // takes the place of the last one, which waits aside until it has.
    checkpoint::save_json(&checkpoint_dir.join("state.json"), &state)?;
    let (current, old) = (dir.join("checkpoint"), dir.join(CHECKPOINT_OLD));
    if old.exists() {
        std::fs::remove_dir_all(&old).map_err(io(&old))?;
    }
    if current.exists() {
        std::fs::rename(&current, &old).map_err(io(&current))?;
    }
    std::fs::rename(&checkpoint_dir, &current).map_err(io(&current))?;
    if old.exists() {
        std::fs::remove_dir_all(&old).map_err(io(&old))?;
    }
    forget_old_episodes(dir, replay)?;
    let mut prefixes = vec![dir.join("policy")];
    if improved {
        prefixes.push(dir.join("best"));
    }
    let epochs = metrics.len();
    if options.snapshot_every > 0 && epochs.is_multiple_of(options.snapshot_every) {
        prefixes.push(dir.join(format!("snapshots/epoch-{:04}", epochs - 1)));
    }
    Policy::save(agent, &prefixes, card_metadata(options, start, metrics))?;
    let csv: Vec<String> = std::iter::once(CSV_HEADER.to_string())
        .chain(metrics.iter().map(EpochMetrics::csv_row))
        .collect();
    checkpoint::write_atomically(&dir.join("metrics.csv"), (csv.join("\n") + "\n").as_bytes())?;
    if let Err(e) = plot_learning_curve(dir, &options.label, options.seed, metrics) {
        eprintln!("warning: no learning-curve plot: {e}");
    }
    Ok(())
}

/// Removes the epochs' episode files that the checkpoint no longer lists: those the buffer has
/// let go, and any an interrupted epoch wrote beyond it.
fn forget_old_episodes(dir: &Path, replay: &ReplayLog) -> Result<(), TrainError> {
    let folder = dir.join("replay");
    let Ok(entries) = std::fs::read_dir(&folder) else {
        return Ok(());
    };
    let kept: std::collections::HashSet<PathBuf> = replay
        .segments
        .iter()
        .map(|s| Segment::path(dir, s.epoch))
        .collect();
    for entry in entries.flatten() {
        let path = entry.path();
        if !kept.contains(&path) {
            std::fs::remove_file(&path).map_err(|e| CheckpointError::Io {
                path: path.clone(),
                message: e.to_string(),
            })?;
        }
    }
    Ok(())
}

/// Puts back the last complete checkpoint of the run in `dir` where a run killed while
/// swapping one in left it: the new one is complete once its state is written, and the old
/// one is whole until the new one has taken its place.
fn recover_checkpoint(dir: &Path) -> Result<(), TrainError> {
    let current = dir.join("checkpoint");
    if current.join("state.json").exists() {
        return Ok(());
    }
    for aside in [CHECKPOINT_NEW, CHECKPOINT_OLD] {
        let aside = dir.join(aside);
        if aside.join("state.json").exists() {
            if current.exists() {
                std::fs::remove_dir_all(&current).map_err(|e| CheckpointError::Io {
                    path: current.clone(),
                    message: e.to_string(),
                })?;
            }
            std::fs::rename(&aside, &current).map_err(|e| CheckpointError::Io {
                path: aside.clone(),
                message: e.to_string(),
            })?;
            return Ok(());
        }
    }
    Ok(())
}

/// Draws DIR/success.png: test success against training episodes.
fn plot_learning_curve(
    dir: &Path,
    label: &str,
    seed: u64,
    metrics: &[EpochMetrics],
) -> Result<PathBuf, String> {
    let curve = Series {
        label: format!("test success (seed {seed})"),
        points: metrics
            .iter()
            .map(|m| (m.episodes as f64, m.test_success))
            .collect(),
        band: None,
    };
    let path = dir.join("success.png");
    line_plot(
        &path,
        label,
        "training episodes",
        "test success rate",
        1.0,
        &[curve],
    )?;
    Ok(path)
}

/// Redraws the learning curve of the run in `dir` from its checkpoint, for a run trained
/// where plots could not be drawn (a machine without fonts); returns the PNG's path.
pub fn replot(dir: &Path) -> Result<PathBuf, TrainError> {
    let run = RunCurve::read(dir)?;
    plot_learning_curve(dir, &run.label, run.seed, &run.metrics).map_err(TrainError::Plot)
}

/// A training run's learning curve, as its checkpoint keeps it, with what the run was: its
/// label, seed, hyperparameters and the environment facts its first call named.
pub struct RunCurve {
    pub label: String,
    pub seed: u64,
    pub config: DdpgHerConfig,
    pub metrics: Vec<EpochMetrics>,
    /// The environment facts of the policy cards (`null` for checkpoints older than them).
    pub environment: serde_json::Value,
}

impl RunCurve {
    /// Reads the curve of the run in `dir` (from `checkpoint/state.json`).
    pub fn read(dir: &Path) -> Result<RunCurve, TrainError> {
        let path = dir.join("checkpoint").join("state.json");
        if !path.exists() {
            return Err(TrainError::Plot(format!(
                "{} is not a training run's folder (it has no checkpoint/state.json)",
                dir.display()
            )));
        }
        let state: TrainState = checkpoint::load_json(&path)?;
        Ok(RunCurve {
            label: state.label,
            seed: state.seed,
            config: state.config,
            metrics: state.metrics,
            environment: state
                .start
                .map_or(serde_json::Value::Null, |s| s.environment),
        })
    }
}

/// The run in `dir` loaded to go on: its networks, normalisers and (where its checkpoint kept
/// them) its optimisers' moments, step count, noise stream and replay buffer; then its
/// metrics, how it began and its replay log. `None` if it has no checkpoint yet.
fn resume(
    agent: &mut Agent,
    buffer: &mut HerBuffer,
    dir: &Path,
    options: &TrainOptions,
) -> Result<Option<(Vec<EpochMetrics>, RunStart, ReplayLog)>, TrainError> {
    recover_checkpoint(dir)?;
    let checkpoint_dir = dir.join("checkpoint");
    if !checkpoint_dir.join("state.json").exists() {
        return Ok(None);
    }
    let resumed = load_checkpoint(agent, &checkpoint_dir, None, |state, agent| {
        let at = checkpoint_dir.display();
        let refusal = if state.dims != agent.dims || state.config != agent.config {
            format!(
                "{at} was trained with other sizes or hyperparameters ({:?}); use a new --out folder",
                state.dims
            )
        } else if state.label != options.label {
            format!(
                "{at} is a run of {}, not {}; pass the same environment and mode",
                state.label, options.label
            )
        } else if state.seed != options.seed {
            format!(
                "{at} was trained with seed {}, not {}",
                state.seed, options.seed
            )
        } else {
            return Ok(());
        };
        Err(TrainError::Resume(refusal))
    })?;
    if agent.config.anchor > 0.0 {
        let path = checkpoint_dir.join(ANCHOR_FILE);
        let [observation_norm, goal_norm] = resumed.anchor_normalizers.ok_or_else(|| {
            mismatch(
                &path,
                "state.json keeps no normalisers for the anchor".into(),
            )
        })?;
        let saved = SavedAnchor {
            actor: checkpoint::load_tensors(&path)?,
            observation_norm,
            goal_norm,
        };
        agent
            .load_anchor(saved)
            .map_err(|e| mismatch(&path, e.to_string()))?;
    }
    let replay = match (&resumed.learner, &resumed.replay) {
        (Some(learner), Some(replay)) => {
            let records = (0..learner.parameter_ids.len())
                .map(|k| {
                    let path = checkpoint_dir.join(OPTIMIZER_FILES[k]);
                    burn::optim::OptimizerRecord::load(&path).map_err(|e| {
                        TrainError::Checkpoint(CheckpointError::Corrupt {
                            path,
                            message: e.to_string(),
                        })
                    })
                })
                .collect::<Result<Vec<_>, _>>()?;
            agent
                .load_learner_state(learner, records)
                .map_err(|message| mismatch(&checkpoint_dir, message))?;
            refill(buffer, dir, agent.dims, replay)?;
            replay.clone()
        }
        _ => {
            eprintln!(
                "warning: {} keeps no optimiser moments or replay buffer (an older checkpoint): \
                 the run goes on with fresh moments and an empty buffer",
                checkpoint_dir.display()
            );
            ReplayLog::default()
        }
    };
    let start = resumed.start.unwrap_or_else(|| RunStart {
        init_from: resumed.init_from,
        ..RunStart::of(options)
    });
    Ok(Some((resumed.metrics, start, replay)))
}

/// Refills the empty `buffer` from the episode files `replay` lists.
fn refill(
    buffer: &mut HerBuffer,
    dir: &Path,
    dims: Dims,
    replay: &ReplayLog,
) -> Result<(), TrainError> {
    let mut episodes = Vec::new();
    for segment in &replay.segments {
        let path = Segment::path(dir, segment.epoch);
        let bytes = std::fs::read(&path).map_err(|e| CheckpointError::Io {
            path: path.clone(),
            message: format!("{e}; the checkpoint needs it to refill the replay buffer"),
        })?;
        let read =
            episodes_from_bytes(dims, &bytes).map_err(|message| CheckpointError::Corrupt {
                path: path.clone(),
                message,
            })?;
        episodes.extend(read);
    }
    let first = replay.segments.first().map_or(0, |s| s.first);
    buffer
        .restore(first, episodes, replay.position)
        .map_err(|message| mismatch(&dir.join("replay"), message))?;
    Ok(())
}

/// Takes the networks and normalisers of the run in `dir`, for a new run. The run may have had
/// a shorter goal, as when a success test gains a part (LayerOpEnv's good state), or a shorter
/// observation, as when the policy is shown more (LayerOpEnv's view of the misalignment): the
/// new inputs then start with zero weights, see [`widen_inputs`]. The new run's hidden layers
/// may be wider than the saved ones, see [`embed_in_wider`].
fn warm_start(agent: &mut Agent, dir: &Path, actor_from: Option<&Path>) -> Result<(), TrainError> {
    let checkpoint_dir = dir.join("checkpoint");
    if !checkpoint_dir.join("state.json").exists() {
        return Err(TrainError::WarmStart(format!(
            "{} holds no checkpoint (a training run's folder has checkpoint/state.json)",
            dir.display()
        )));
    }
    load_checkpoint(agent, &checkpoint_dir, actor_from, |state, agent| {
        let (saved, needed) = (state.dims, agent.dims);
        if can_start_from(saved, needed) {
            Ok(())
        } else {
            Err(TrainError::WarmStart(format!(
                "{} has networks for {saved:?}, this environment needs {needed:?}",
                checkpoint_dir.display(),
            )))
        }
    })
    .map(drop)
}

/// Takes the actor (and its target) and the normalisers of the policy at `prefix` for a new
/// run whose critic starts afresh. The policy may have had a shorter goal or observation, or
/// narrower hidden layers, as for [`warm_start`].
fn warm_start_actor(agent: &mut Agent, prefix: &Path) -> Result<(), TrainError> {
    let (mut actor, card) = read_policy(prefix)?;
    let (saved, needed) = (card.dims, agent.dims);
    if !can_start_from(saved, needed) {
        return Err(TrainError::WarmStart(format!(
            "the policy {} is for {saved:?}, this environment needs {needed:?}",
            prefix.display()
        )));
    }
    let (mut observation_norm, mut goal_norm) = (card.observation_norm, card.goal_norm);
    widen_inputs(
        &mut [("actor", &mut actor)],
        (&mut observation_norm, &mut goal_norm),
        saved,
        needed,
    )
    .map_err(|message| mismatch(prefix, message))?;
    let mut networks = agent.networks();
    // The run's fresh actor lends its new units to the wider layers, then the saved one
    // embedded in it takes its place.
    let fresh_actor = std::mem::take(&mut networks[0]);
    embed_in_wider(std::slice::from_mut(&mut actor), [fresh_actor], prefix)?;
    (networks[0], networks[2]) = (actor.clone(), actor);
    agent
        .load_networks(&networks)
        .map_err(|e| mismatch(prefix, e.to_string()))?;
    agent.observation_norm = observation_norm;
    agent.goal_norm = goal_norm;
    Ok(())
}

/// Fits saved networks to this run's hidden layers where the run's are wider, each into the
/// fresh network of the run in the same place (see [`crate::params::embed_in_wider`]): a
/// warm start onto a wider network computes what the saved one did, and learns with the room
/// the new units give. Networks of the run's own widths are taken as saved.
fn embed_in_wider(
    saved: &mut [Vec<crate::params::NamedTensor>],
    fresh: impl IntoIterator<Item = Vec<crate::params::NamedTensor>>,
    from: &Path,
) -> Result<(), TrainError> {
    for (network, fresh) in saved.iter_mut().zip(fresh) {
        *network = crate::params::embed_in_wider(network, fresh).map_err(|m| mismatch(from, m))?;
    }
    Ok(())
}

/// The actor's weights and the card of the policy at `prefix`.
fn read_policy(
    prefix: &Path,
) -> Result<(Vec<crate::params::NamedTensor>, crate::policy::PolicyCard), TrainError> {
    let (_, card, tensors) = crate::policy::read_single(prefix, "trained from")?;
    Ok((tensors, card))
}

/// The error for saved networks at `path` that do not fit, saying why.
fn mismatch(path: &Path, message: String) -> TrainError {
    TrainError::Checkpoint(CheckpointError::Mismatch {
        path: path.to_path_buf(),
        message,
    })
}

/// Whether networks for `saved` sizes can start a run that needs `needed`: the same action,
/// and an observation and a goal no longer (new parts are appended to each).
fn can_start_from(saved: Dims, needed: Dims) -> bool {
    saved.observation <= needed.observation
        && saved.action == needed.action
        && saved.goal <= needed.goal
}

/// Gives networks saved for `saved` sizes the inputs that `needed` appends to the observation
/// and to the goal: zero weights in each first layer, so every network computes what it did,
/// and statistics that keep the old inputs and feed the new ones as they are. The first layer
/// reads the observation, then the goal (then, in a critic, the action).
fn widen_inputs(
    networks: &mut [(&str, &mut Vec<crate::params::NamedTensor>)],
    (observation_norm, goal_norm): (
        &mut crate::normalizer::Normalizer,
        &mut crate::normalizer::Normalizer,
    ),
    saved: Dims,
    needed: Dims,
) -> Result<(), String> {
    // The goal's new inputs first, so that the observation's, inserted before them, leave
    // their place where it was computed.
    let insertions = [
        (saved.observation + saved.goal, needed.goal - saved.goal),
        (saved.observation, needed.observation - saved.observation),
    ];
    for (at, extra) in insertions.into_iter().filter(|&(_, extra)| extra > 0) {
        for (name, tensors) in networks.iter_mut() {
            if !crate::params::insert_zero_inputs(tensors, "layers.0.weight", at, extra) {
                return Err(format!(
                    "the {name} network has no first layer with {at} inputs or more"
                ));
            }
        }
    }
    *observation_norm = observation_norm.widened(needed.observation - saved.observation);
    *goal_norm = goal_norm.widened(needed.goal - saved.goal);
    Ok(())
}

/// Loads a checkpoint's networks and normalisers into `agent` once `check` has vetted its
/// saved state, the actor and normalisers from the policy at `actor_from` if given; returns
/// the saved state.
fn load_checkpoint(
    agent: &mut Agent,
    checkpoint_dir: &Path,
    actor_from: Option<&Path>,
    check: impl Fn(&TrainState, &Agent) -> Result<(), TrainError>,
) -> Result<TrainState, TrainError> {
    let mut state: TrainState = checkpoint::load_json(&checkpoint_dir.join("state.json"))?;
    check(&state, agent)?;
    let mut networks: [Vec<crate::params::NamedTensor>; 4] = Default::default();
    for (slot, name) in networks.iter_mut().zip(NETWORK_FILES) {
        *slot = checkpoint::load_tensors(&checkpoint_dir.join(format!("{name}.safetensors")))?;
    }
    if let Some(prefix) = actor_from {
        let (actor, card) = read_policy(prefix)?;
        if card.dims != state.dims {
            return Err(mismatch(
                checkpoint_dir,
                format!(
                    "the policy {} has sizes {:?}, the run's networks {:?}: pass a policy of that run",
                    prefix.display(),
                    card.dims,
                    state.dims
                ),
            ));
        }
        (networks[0], networks[2]) = (actor.clone(), actor);
        (state.observation_norm, state.goal_norm) = (card.observation_norm, card.goal_norm);
    }
    // A run with twin critics warm-started from a DDPG run keeps its second critic as made:
    // a copy of the first would learn the same targets on the same batches and stay a copy.
    let twin_saved = checkpoint_dir.join(format!("{}.safetensors", TWIN_FILES[0]));
    let mut twin: Option<[Vec<crate::params::NamedTensor>; 2]> = None;
    if agent.twin_networks().is_some() && twin_saved.exists() {
        let mut saved: [Vec<crate::params::NamedTensor>; 2] = Default::default();
        for (slot, name) in saved.iter_mut().zip(TWIN_FILES) {
            *slot = checkpoint::load_tensors(&checkpoint_dir.join(format!("{name}.safetensors")))?;
        }
        twin = Some(saved);
    }
    if state.dims != agent.dims {
        let mut named: Vec<_> = NETWORK_FILES.into_iter().zip(networks.iter_mut()).collect();
        named.extend(
            twin.iter_mut()
                .flat_map(|t| TWIN_FILES.into_iter().zip(t.iter_mut())),
        );
        widen_inputs(
            &mut named,
            (&mut state.observation_norm, &mut state.goal_norm),
            state.dims,
            agent.dims,
        )
        .map_err(|message| mismatch(checkpoint_dir, message))?;
    }
    embed_in_wider(&mut networks, agent.networks(), checkpoint_dir)?;
    if let (Some(twin), Some(fresh)) = (twin.as_mut(), agent.twin_networks()) {
        embed_in_wider(twin, fresh, checkpoint_dir)?;
    }
    agent
        .load_networks(&networks)
        .map_err(|e| mismatch(checkpoint_dir, e.to_string()))?;
    if let Some(twin) = &twin {
        agent
            .load_twin_networks(twin)
            .map_err(|e| mismatch(checkpoint_dir, e.to_string()))?;
    }
    agent.observation_norm = state.observation_norm.clone();
    agent.goal_norm = state.goal_norm.clone();
    Ok(state)
}
