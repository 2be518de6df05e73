//! # dexcube-py
//!
//! The Rust side of the `dexcube` Python package (`dexcube._dexcube`), exposing what the Rust
//! crates already have; the Python side (`python/dexcube`) wraps it in Gymnasium's shapes.
//!
//! - [`Env`]: one CubeRotEnv or LayerOpEnv, built from an environment's settings as JSON
//!   (`dexcube_env::EnvSettings`), with reset, step, the pure reward for HER and rendering;
//! - [`VecEnv`]: many of them stepped on Rust threads with the GIL released, arrays in and out
//!   as bytes of little-endian `f64`, an environment reset in the step its episode ends
//!   (Gymnasium's same-step autoreset);
//! - [`solve`] and [`scramble`]: the optimal planner, with the CLI's facelet convention;
//! - [`Policy`]: a shipped or trained policy's deterministic action.
//!
//! Every failure is a Python exception with the message the CLI would print.

use std::path::PathBuf;
use std::sync::Arc;

use dexcube_cube::{
    DistanceTable, Facelets, Method, Position, format_moves, parse_moves, scrambles_at_distance,
};
use dexcube_env::{EnvSettings, Goal, GoalEnv, Observation, SimulatedEnv, Skill, Transition};
use dexcube_sim::render::{DEFAULT_CAMERA, FrameRenderer};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

/// A ValueError carrying `message`.
fn bad(message: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(message.to_string())
}

fn skill(name: &str) -> PyResult<Skill> {
    match name {
        "rot" => Ok(Skill::Rot),
        "layer" => Ok(Skill::Layer),
        other => Err(bad(format!(
            "unknown skill '{other}': use 'rot' or 'layer'"
        ))),
    }
}

/// The environments an environment's settings (JSON) make for `skill`, with its label.
fn maker(skill_name: &str, settings: &str) -> PyResult<(dexcube_env::EnvMaker, String)> {
    let skill = skill(skill_name)?;
    let settings: EnvSettings = serde_json::from_str(settings).map_err(bad)?;
    let spec = settings.resolve(skill).map_err(bad)?;
    let starts = match &spec.starts {
        Some(setting) => Some(
            dexcube_rl::start_file::load_starts(&setting.path)
                .map_err(bad)?
                .0
                .into(),
        ),
        None => None,
    };
    Ok((spec.maker(starts).map_err(bad)?, spec.name()))
}

/// One step's or reset's observation as three lists.
type Parts = (Vec<f64>, Vec<f64>, Vec<f64>);

fn parts(o: Observation) -> Parts {
    (o.observation, o.achieved_goal, o.desired_goal)
}

/// What `info` holds, as Gymnasium-Robotics names it.
fn info<'py>(py: Python<'py>, info: &dexcube_env::Info) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("is_success", info.is_success)?;
    dict.set_item("position_error", info.position_error)?;
    dict.set_item("angle_error", info.angle_error)?;
    dict.set_item("dropped", info.dropped)?;
    dict.set_item(
        "physics_error",
        info.physics_error.as_ref().map(|e| e.to_string()),
    )?;
    Ok(dict)
}

/// The rewards of `n` (achieved, desired) goal rows, laid out row after row.
fn rewards(goal: &dyn Goal, achieved: &[f64], desired: &[f64]) -> PyResult<Vec<f64>> {
    let size = goal.size();
    if achieved.len() != desired.len() || !achieved.len().is_multiple_of(size) {
        return Err(bad(format!(
            "achieved and desired goals must be rows of {size} numbers alike, not {} and {} numbers",
            achieved.len(),
            desired.len()
        )));
    }
    Ok(achieved
        .chunks(size)
        .zip(desired.chunks(size))
        .map(|(a, d)| goal.compute_reward(a, d))
        .collect())
}

/// One CubeRotEnv or LayerOpEnv.
#[pyclass(unsendable)]
pub struct Env {
    env: Box<dyn SimulatedEnv>,
    renderer: Option<FrameRenderer>,
    label: String,
}

#[pymethods]
impl Env {
    /// `skill` is 'rot' or 'layer'; `settings` an environment's settings as JSON.
    #[new]
    fn new(skill: &str, settings: &str) -> PyResult<Env> {
        let (make, label) = maker(skill, settings)?;
        Ok(Env {
            env: make(),
            renderer: None,
            label,
        })
    }

    /// The environment's name, as runs and policy cards name it.
    #[getter]
    fn label(&self) -> String {
        self.label.clone()
    }

    /// (observation, goal, action) sizes.
    fn spaces(&self) -> (usize, usize, usize) {
        let s = self.env.spaces();
        (s.observation, s.goal, s.action)
    }

    /// Starts an episode; a seed re-seeds the environment's generator.
    #[pyo3(signature = (seed=None))]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: Option<u64>,
    ) -> PyResult<(Parts, Bound<'py, PyDict>)> {
        let (o, i) = self.env.reset(seed);
        Ok((parts(o), info(py, &i)?))
    }

    /// One step: (observation parts, reward, terminated, truncated, info).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: Vec<f64>,
    ) -> PyResult<(Parts, f64, bool, bool, Bound<'py, PyDict>)> {
        let expected = self.env.spaces().action;
        if action.len() != expected {
            return Err(bad(format!(
                "an action has {expected} numbers, not {}",
                action.len()
            )));
        }
        let t: Transition = self.env.step(&action);
        let info = info(py, &t.info)?;
        Ok((
            parts(t.observation),
            t.reward,
            t.terminated,
            t.truncated,
            info,
        ))
    }

    /// The rewards of rows of achieved and desired goals, flattened, as HER relabels them.
    fn compute_reward(&self, achieved: Vec<f64>, desired: Vec<f64>) -> PyResult<Vec<f64>> {
        rewards(self.env.goal().as_ref(), &achieved, &desired)
    }

    /// The scene as it is now, seen by the scene's camera: (width, height, RGB bytes).
    #[pyo3(signature = (width=480, height=360))]
    fn render<'py>(
        &mut self,
        py: Python<'py>,
        width: usize,
        height: usize,
    ) -> PyResult<(usize, usize, Bound<'py, PyBytes>)> {
        let stale = self
            .renderer
            .as_ref()
            .is_none_or(|r| r.size() != (width, height));
        if stale {
            let renderer = FrameRenderer::new(self.env.sim(), width, height, DEFAULT_CAMERA)
                .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
            self.renderer = Some(renderer);
        }
        let renderer = self.renderer.as_mut().expect("made above");
        let frame = renderer
            .render(self.env.sim_mut())
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        Ok((frame.width, frame.height, PyBytes::new(py, &frame.rgb)))
    }
}

/// Little-endian `f64` bytes of `values`.
fn to_bytes<'py>(py: Python<'py>, values: &[f64]) -> Bound<'py, PyBytes> {
    let mut out = Vec::with_capacity(values.len() * 8);
    values.iter().for_each(|v| out.extend(v.to_le_bytes()));
    PyBytes::new(py, &out)
}

/// What a vector env's step or reset gives back: flattened arrays as `f64` bytes (observations,
/// achieved goals, desired goals, rewards), then per environment terminated, truncated, success,
/// dropped, the final observation of an episode that ended (else None) and any physics error.
type VecOut<'py> = (
    [Bound<'py, PyBytes>; 4],
    Vec<bool>,
    Vec<bool>,
    Vec<bool>,
    Vec<bool>,
    Vec<Option<Parts>>,
    Vec<Option<String>>,
);

/// Many environments of one kind stepped together on Rust threads.
#[pyclass(unsendable)]
pub struct VecEnv {
    envs: dexcube_env::VecEnv<Box<dyn GoalEnv>>,
    goal: Arc<dyn Goal>,
}

/// One environment's outcome inside a vector step.
struct Slot {
    o: Observation,
    reward: f64,
    terminated: bool,
    truncated: bool,
    info: dexcube_env::Info,
    final_observation: Option<Observation>,
}

fn gather<'py>(py: Python<'py>, slots: Vec<Slot>) -> VecOut<'py> {
    let (mut obs, mut achieved, mut desired, mut reward) = (vec![], vec![], vec![], vec![]);
    let (mut terminated, mut truncated, mut success, mut dropped) =
        (vec![], vec![], vec![], vec![]);
    let (mut finals, mut errors) = (vec![], vec![]);
    for s in slots {
        obs.extend(&s.o.observation);
        achieved.extend(&s.o.achieved_goal);
        desired.extend(&s.o.desired_goal);
        reward.push(s.reward);
        terminated.push(s.terminated);
        truncated.push(s.truncated);
        success.push(s.info.is_success);
        dropped.push(s.info.dropped);
        finals.push(s.final_observation.map(parts));
        errors.push(s.info.physics_error.map(|e| e.to_string()));
    }
    (
        [
            to_bytes(py, &obs),
            to_bytes(py, &achieved),
            to_bytes(py, &desired),
            to_bytes(py, &reward),
        ],
        terminated,
        truncated,
        success,
        dropped,
        finals,
        errors,
    )
}

#[pymethods]
impl VecEnv {
    #[new]
    fn new(skill: &str, settings: &str, num_envs: usize, num_threads: usize) -> PyResult<VecEnv> {
        if num_envs == 0 || num_threads == 0 {
            return Err(bad("num_envs and num_threads must be at least 1"));
        }
        let (make, _) = maker(skill, settings)?;
        let envs: Vec<Box<dyn GoalEnv>> =
            (0..num_envs).map(|_| make() as Box<dyn GoalEnv>).collect();
        let goal = envs[0].goal();
        Ok(VecEnv {
            envs: dexcube_env::VecEnv::new(envs, num_threads),
            goal,
        })
    }

    fn __len__(&self) -> usize {
        self.envs.len()
    }

    /// (observation, goal, action) sizes.
    fn spaces(&self) -> (usize, usize, usize) {
        let s = self.envs.envs()[0].spaces();
        (s.observation, s.goal, s.action)
    }

    /// Resets every environment, environment i with seed + i (or each continuing its own
    /// generator without a seed).
    #[pyo3(signature = (seed=None))]
    fn reset<'py>(&mut self, py: Python<'py>, seed: Option<u64>) -> VecOut<'py> {
        let envs = &mut self.envs;
        let reset = py.detach(|| match seed {
            Some(seed) => envs.reset(seed),
            None => {
                let each: Vec<_> = envs.envs_mut().iter_mut().map(|e| e.reset(None)).collect();
                each
            }
        });
        let slots = reset
            .into_iter()
            .map(|(o, info)| Slot {
                o,
                reward: 0.0,
                terminated: false,
                truncated: false,
                info,
                final_observation: None,
            })
            .collect();
        gather(py, slots)
    }

    /// Steps every environment with its row of `actions` (`f64` bytes, environments × action
    /// size). One whose episode ends is reset at once, continuing its own generator: its
    /// observation is the next episode's first, and its final observation comes beside it.
    fn step<'py>(&mut self, py: Python<'py>, actions: &[u8]) -> PyResult<VecOut<'py>> {
        let (n, size) = (self.envs.len(), self.envs.envs()[0].spaces().action);
        if actions.len() != n * size * 8 {
            return Err(bad(format!(
                "actions must be {n} rows of {size} float64 numbers ({} bytes), not {} bytes",
                n * size * 8,
                actions.len()
            )));
        }
        let rows: Vec<Vec<f64>> = actions
            .chunks_exact(size * 8)
            .map(|row| {
                row.chunks_exact(8)
                    .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
                    .collect()
            })
            .collect();
        let envs = &mut self.envs;
        let stepped = py.detach(|| envs.step(&rows));
        let slots = stepped
            .into_iter()
            .map(|step| {
                let t = step.transition;
                let (o, final_observation) = match step.reset {
                    Some((first, _)) => (first, Some(t.observation)),
                    None => (t.observation, None),
                };
                Slot {
                    o,
                    reward: t.reward,
                    terminated: t.terminated,
                    truncated: t.truncated,
                    info: t.info,
                    final_observation,
                }
            })
            .collect();
        Ok(gather(py, slots))
    }

    /// The rewards of rows of achieved and desired goals, flattened.
    fn compute_reward(&self, achieved: Vec<f64>, desired: Vec<f64>) -> PyResult<Vec<f64>> {
        rewards(self.goal.as_ref(), &achieved, &desired)
    }
}

/// The optimal (quarter-turn) solution of a cube given as 24 facelet letters, faces in order
/// U R F D L B, as a list of moves.
#[pyfunction]
#[pyo3(signature = (facelets, method="table"))]
fn solve(facelets: &str, method: &str) -> PyResult<Vec<String>> {
    let cube = Facelets::parse(facelets).map_err(|e| bad(format!("not a valid cube: {e}")))?;
    let method = match method {
        "table" => Method::Table,
        "ida" => Method::Ida,
        other => {
            return Err(bad(format!(
                "unknown method '{other}': use 'table' or 'ida'"
            )));
        }
    };
    let solution = method.solver().solve(&Position::of(&cube));
    Ok(format_moves(&solution)
        .split_whitespace()
        .map(str::to_string)
        .collect())
}

/// The cube a move sequence ("R U F' D2") makes from solved, as 24 facelet letters.
#[pyfunction]
fn apply_moves(moves: &str) -> PyResult<String> {
    let moves = parse_moves(moves).map_err(|e| bad(format!("cannot read the moves: {e}")))?;
    Ok(Facelets::SOLVED.apply_all(&moves).to_string())
}

/// `count` cubes drawn uniformly at `distance` quarter turns from solved, from `seed`: each
/// (facelets, the moves that make it from solved).
#[pyfunction]
#[pyo3(signature = (distance, count=1, seed=0))]
fn scramble(distance: usize, count: usize, seed: u64) -> PyResult<Vec<(String, Vec<String>)>> {
    if distance > 14 {
        return Err(bad(format!(
            "no 2x2x2 position lies {distance} quarter turns from solved; the largest distance is 14"
        )));
    }
    let table = DistanceTable::build();
    Ok(scrambles_at_distance(&table, distance, count, seed)
        .into_iter()
        .map(|s| {
            let moves = format_moves(&s.moves)
                .split_whitespace()
                .map(str::to_string)
                .collect();
            (s.facelets.to_string(), moves)
        })
        .collect())
}

/// A trained policy: its deterministic action for an observation and the goal it is shown.
#[pyclass]
pub struct Policy {
    policy: dexcube_rl::Policy,
    label: String,
}

#[pymethods]
impl Policy {
    /// Loads the policy at `prefix` (`models/rot` for models/rot.safetensors and .json).
    #[staticmethod]
    fn load(prefix: PathBuf) -> PyResult<Policy> {
        let policy =
            dexcube_rl::Policy::load(&prefix, &burn::prelude::Device::flex()).map_err(bad)?;
        let label = policy.card.metadata["label"]
            .as_str()
            .unwrap_or("a policy")
            .to_string();
        Ok(Policy { policy, label })
    }

    /// What the policy was trained on.
    #[getter]
    fn label(&self) -> String {
        self.label.clone()
    }

    /// (observation, goal, action) sizes it was trained for.
    fn spaces(&self) -> (usize, usize, usize) {
        let d = self.policy.card.dims;
        (d.observation, d.goal, d.action)
    }

    /// The action for one observation and goal (an ensemble's: its members' mean).
    fn act(&self, observation: Vec<f64>, goal: Vec<f64>) -> PyResult<Vec<f64>> {
        let d = self.policy.card.dims;
        if observation.len() < d.observation || goal.len() != d.goal {
            return Err(bad(format!(
                "the policy takes an observation of {} numbers and a goal of {}, not {} and {}",
                d.observation,
                d.goal,
                observation.len(),
                goal.len()
            )));
        }
        Ok(self.policy.act(&observation, &goal))
    }
}

#[pymodule]
fn _dexcube(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Env>()?;
    m.add_class::<VecEnv>()?;
    m.add_class::<Policy>()?;
    m.add_function(wrap_pyfunction!(solve, m)?)?;
    m.add_function(wrap_pyfunction!(scramble, m)?)?;
    m.add_function(wrap_pyfunction!(apply_moves, m)?)?;
    Ok(())
}
