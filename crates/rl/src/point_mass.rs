//! A small goal-conditioned task to prove the learner before the hand: a point mass in the
//! square [-1, 1]², moved by a velocity action, must reach a goal within 0.05 in 50 steps,
//! under the same sparse 0/-1 reward. Random actions almost never succeed, so learning it
//! quickly shows that DDPG and the HER relabelling are wired right.

use std::sync::Arc;

use dexcube_env::{Goal, GoalEnv, Info, Observation, Spaces, Transition};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Steps per episode.
pub const POINT_MASS_STEPS: usize = 50;

/// Success radius.
const RADIUS: f64 = 0.05;

/// Reaching: success within `RADIUS` of the goal.
pub struct PointGoal;

impl Goal for PointGoal {
    fn size(&self) -> usize {
        2
    }

    fn errors(&self, achieved: &[f64], desired: &[f64]) -> (f64, f64) {
        (
            (achieved[0] - desired[0]).hypot(achieved[1] - desired[1]),
            0.0,
        )
    }

    fn is_success(&self, achieved: &[f64], desired: &[f64]) -> bool {
        self.errors(achieved, desired).0 < RADIUS
    }
}

pub struct PointMassEnv {
    position: [f64; 2],
    goal: [f64; 2],
    steps: usize,
    rng: ChaCha8Rng,
}

impl Default for PointMassEnv {
    fn default() -> Self {
        PointMassEnv {
            position: [0.0; 2],
            goal: [0.0; 2],
            steps: 0,
            rng: ChaCha8Rng::seed_from_u64(0),
        }
    }
}

impl PointMassEnv {
    fn observe(&self) -> Observation {
        Observation {
            observation: self.position.to_vec(),
            achieved_goal: self.position.to_vec(),
            desired_goal: self.goal.to_vec(),
        }
    }

    fn info(&self, observation: &Observation) -> Info {
        let (a, d) = (&observation.achieved_goal, &observation.desired_goal);
        Info {
            is_success: PointGoal.is_success(a, d),
            position_error: PointGoal.errors(a, d).0,
            ..Info::default()
        }
    }
}

impl GoalEnv for PointMassEnv {
    fn spaces(&self) -> Spaces {
        Spaces {
            observation: 2,
            goal: 2,
            action: 2,
        }
    }

    fn goal(&self) -> Arc<dyn Goal> {
        Arc::new(PointGoal)
    }

    fn reset(&mut self, seed: Option<u64>) -> (Observation, Info) {
        if let Some(seed) = seed {
            self.rng = ChaCha8Rng::seed_from_u64(seed);
        }
        self.position = [
            self.rng.random_range(-1.0..1.0),
            self.rng.random_range(-1.0..1.0),
        ];
        self.goal = [
            self.rng.random_range(-1.0..1.0),
            self.rng.random_range(-1.0..1.0),
        ];
        self.steps = 0;
        let observation = self.observe();
        let info = self.info(&observation);
        (observation, info)
    }

    fn step(&mut self, action: &[f64]) -> Transition {
        for (p, a) in self.position.iter_mut().zip(action) {
            *p = (*p + 0.1 * a.clamp(-1.0, 1.0)).clamp(-1.0, 1.0);
        }
        self.steps += 1;
        let observation = self.observe();
        let info = self.info(&observation);
        Transition {
            reward: PointGoal.compute_reward(&observation.achieved_goal, &observation.desired_goal),
            terminated: false,
            truncated: self.steps >= POINT_MASS_STEPS,
            observation,
            info,
        }
    }
}
