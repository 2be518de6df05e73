//! Many environments stepped together on a pool of threads. Each has its own `MjData` over a
//! shared model and its own random stream, so results depend on the seed alone, not on the
//! thread count or scheduling. An environment whose episode ends is reset on the spot.

use rayon::prelude::*;

use crate::{GoalEnv, Info, Observation, Transition};

/// One environment's step inside a `VecEnv`.
#[derive(Clone, Debug)]
pub struct VecStep {
    /// The step's outcome; its observation is the last of the episode when it ended.
    pub transition: Transition,
    /// When the episode ended: the first observation of the next one.
    pub reset: Option<(Observation, Info)>,
}

pub struct VecEnv<E: GoalEnv> {
    envs: Vec<E>,
    /// None for one thread: the calling thread steps the environments itself, saving the
    /// two context switches per step that handing work to a pool costs.
    pool: Option<rayon::ThreadPool>,
}

impl<E: GoalEnv> VecEnv<E> {
    /// Steps `envs` on `threads` threads.
    pub fn new(envs: Vec<E>, threads: usize) -> VecEnv<E> {
        let pool = (threads > 1).then(|| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .thread_name(|i| format!("dexcube-env-{i}"))
                .build()
                .expect("a thread pool starts")
        });
        VecEnv { envs, pool }
    }

    /// Runs `work` on each environment, on the pool if there is one, results in order.
    fn each<T: Send>(&mut self, work: impl Fn(usize, &mut E) -> T + Sync + Send) -> Vec<T> {
        match &self.pool {
            Some(pool) => pool.install(|| {
                self.envs
                    .par_iter_mut()
                    .enumerate()
                    .map(|(i, e)| work(i, e))
                    .collect()
            }),
            None => self
                .envs
                .iter_mut()
                .enumerate()
                .map(|(i, e)| work(i, e))
                .collect(),
        }
    }

    pub fn len(&self) -> usize {
        self.envs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.envs.is_empty()
    }

    pub fn envs(&self) -> &[E] {
        &self.envs
    }

    pub fn envs_mut(&mut self) -> &mut [E] {
        &mut self.envs
    }

    /// Resets every environment; environment `i` is seeded with `seed + i`.
    pub fn reset(&mut self, seed: u64) -> Vec<(Observation, Info)> {
        self.each(|i, env| env.reset(Some(seed.wrapping_add(i as u64))))
    }

    /// Steps environment `i` with `actions[i]`; an environment whose episode ended (dropped,
    /// blown up or out of steps) is reset, continuing its own random stream.
    pub fn step(&mut self, actions: &[Vec<f64>]) -> Vec<VecStep> {
        assert_eq!(actions.len(), self.envs.len(), "one action per environment");
        self.each(|i, env| {
            let transition = env.step(&actions[i]);
            let reset = (transition.terminated || transition.truncated).then(|| env.reset(None));
            VecStep { transition, reset }
        })
    }
}
