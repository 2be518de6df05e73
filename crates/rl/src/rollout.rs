//! Collecting whole episodes from a `VecEnv` with the agent's policy, with exploration for
//! training or deterministically for tests.

use dexcube_env::{GoalEnv, Observation, VecEnv};
use rand_chacha::ChaCha8Rng;

use crate::agent::Agent;
use crate::replay::Episode;

/// What a batch of episodes achieved.
#[derive(Clone, Copy, Debug, Default)]
pub struct RolloutStats {
    pub episodes: usize,
    /// Episodes that ended in success at their last step.
    pub successes: usize,
    pub steps: usize,
}

impl RolloutStats {
    pub fn success_rate(&self) -> f64 {
        if self.episodes == 0 {
            0.0
        } else {
            self.successes as f64 / self.episodes as f64
        }
    }
}

fn start(episode: &mut Episode, o: &Observation) {
    episode.observation.extend(&o.observation);
    episode.achieved_goal.extend(&o.achieved_goal);
}

/// One episode from each environment, reset with `seed + i`. An environment whose episode
/// ends early (a drop) is left alone, stepping idle, until the others finish.
pub fn rollout<E: GoalEnv>(
    envs: &mut VecEnv<E>,
    agent: &Agent,
    seed: u64,
    mut explore: Option<&mut ChaCha8Rng>,
) -> (Vec<Episode>, RolloutStats) {
    let n = envs.len();
    let mut current: Vec<Observation> = envs.reset(seed).into_iter().map(|(o, _)| o).collect();
    let mut episodes: Vec<Episode> = current
        .iter()
        .map(|o| {
            let mut e = Episode::default();
            start(&mut e, o);
            e
        })
        .collect();
    let mut done = vec![false; n];
    let mut stats = RolloutStats {
        episodes: n,
        ..RolloutStats::default()
    };
    while done.iter().any(|d| !d) {
        let observation: Vec<f64> = current
            .iter()
            .flat_map(|o| o.observation.iter().copied())
            .collect();
        let goal: Vec<f64> = current
            .iter()
            .flat_map(|o| o.desired_goal.iter().copied())
            .collect();
        let actions = agent.act(&observation, &goal, n, explore.as_deref_mut());
        let steps = envs.step(&actions);
        for (i, step) in steps.into_iter().enumerate() {
            let t = step.transition;
            if !done[i] {
                let e = &mut episodes[i];
                e.len += 1;
                e.desired_goal.extend(&current[i].desired_goal);
                e.action.extend(actions[i].iter().map(|&a| a as f32));
                start(e, &t.observation);
                stats.steps += 1;
                if t.terminated || t.truncated {
                    done[i] = true;
                    e.terminated = t.terminated;
                    stats.successes += t.info.is_success as usize;
                }
            }
            current[i] = match step.reset {
                Some((o, _)) => o,
                None => t.observation,
            };
        }
    }
    (episodes, stats)
}
