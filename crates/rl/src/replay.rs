//! The Hindsight Experience Replay buffer: whole episodes are stored, and goals are relabelled
//! when a batch is sampled, with the "future" strategy: with probability k/(k+1) a transition's
//! goal becomes the goal achieved at a uniformly chosen later step of its own episode, and its
//! reward is recomputed by the environment's pure reward function.

use std::collections::VecDeque;
use std::sync::Arc;

use dexcube_env::Goal;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::agent::{Batch, Dims};

/// One episode of `len` steps: observations and achieved goals at steps 0..=len, desired
/// goals and actions at steps 0..len, each row-major.
#[derive(Clone, Debug, Default)]
pub struct Episode {
    pub len: usize,
    pub observation: Vec<f64>,
    pub achieved_goal: Vec<f64>,
    pub desired_goal: Vec<f64>,
    pub action: Vec<f32>,
    /// The episode ended early in an absorbing failure (the object dropped or the physics
    /// blew up), not by running out of steps.
    pub terminated: bool,
}

pub struct HerBuffer {
    dims: Dims,
    capacity: usize,
    episodes: VecDeque<Episode>,
    transitions: usize,
    /// The longest episode ever stored, which the uniform draw over transitions rejects by.
    longest: usize,
    /// Episodes stored over the buffer's life, those that have left included.
    stored: usize,
    future_probability: f64,
    goal: Arc<dyn Goal>,
}

impl HerBuffer {
    /// A buffer of up to `capacity` transitions; the oldest episodes go first.
    pub fn new(
        dims: Dims,
        capacity: usize,
        future_probability: f64,
        goal: Arc<dyn Goal>,
    ) -> HerBuffer {
        HerBuffer {
            dims,
            capacity,
            episodes: VecDeque::new(),
            transitions: 0,
            longest: 0,
            stored: 0,
            future_probability,
            goal,
        }
    }

    pub fn transitions(&self) -> usize {
        self.transitions
    }

    pub fn store(&mut self, episode: Episode) {
        if episode.len == 0 {
            return;
        }
        self.transitions += episode.len;
        self.longest = self.longest.max(episode.len);
        self.stored += 1;
        self.episodes.push_back(episode);
        while self.transitions > self.capacity {
            let old = self.episodes.pop_front().expect("transitions > 0");
            self.transitions -= old.len;
        }
    }

    /// Where the buffer stands, for a checkpoint: episodes stored over its life, how many of
    /// the latest it holds, and its longest episode.
    pub fn position(&self) -> ReplayPosition {
        ReplayPosition {
            stored: self.stored,
            held: self.episodes.len(),
            longest: self.longest,
        }
    }

    /// Refills an empty buffer with `episodes`, the ones stored from number `first` on of a
    /// buffer that stood at `position`: it then holds what that buffer held and draws as it
    /// drew. Fails, saying why, if they do not reach back to its oldest episode.
    pub fn restore(
        &mut self,
        first: usize,
        episodes: Vec<Episode>,
        position: ReplayPosition,
    ) -> Result<(), String> {
        if self.stored != 0 {
            return Err("the buffer to refill already holds episodes".into());
        }
        let oldest = position.stored - position.held.min(position.stored);
        if first > oldest {
            return Err(format!(
                "its episodes begin at number {first}, after the oldest it held, {oldest}"
            ));
        }
        for episode in episodes {
            self.store(episode);
        }
        if first + self.stored != position.stored || self.episodes.len() != position.held {
            return Err(format!(
                "its episodes from number {first} on come to {} stored and {} held, the buffer \
                 stood at {} and {}",
                first + self.stored,
                self.episodes.len(),
                position.stored,
                position.held
            ));
        }
        self.stored = position.stored;
        self.longest = position.longest;
        Ok(())
    }

    /// A transition drawn uniformly over all stored transitions, relabelled as HER does:
    /// its (episode, step) and the step whose achieved goal is its goal.
    fn draw(&self, rng: &mut ChaCha8Rng) -> (&Episode, usize, Option<usize>) {
        loop {
            // Uniform over transitions: an episode drawn uniformly, kept in proportion to its
            // length (rejection), then a step within it.
            let episode = &self.episodes[rng.random_range(0..self.episodes.len())];
            if rng.random_range(0..self.longest) >= episode.len {
                continue;
            }
            let t = rng.random_range(0..episode.len);
            return (episode, t, self.relabel(episode, t, rng));
        }
    }

    /// HER's "future" choice for step `t`: with probability k/(k+1), a uniformly chosen later
    /// step whose achieved goal becomes the goal; otherwise `None`, keeping the real goal.
    fn relabel(&self, episode: &Episode, t: usize, rng: &mut ChaCha8Rng) -> Option<usize> {
        (rng.random::<f64>() < self.future_probability)
            .then(|| rng.random_range(t + 1..=episode.len))
    }

    /// Step `t`'s goal, or the achieved goal of step `future` when relabelled.
    fn goal_of<'e>(&self, episode: &'e Episode, t: usize, future: Option<usize>) -> &'e [f64] {
        let dgoal = self.dims.goal;
        match future {
            Some(f) => &episode.achieved_goal[f * dgoal..(f + 1) * dgoal],
            None => &episode.desired_goal[t * dgoal..(t + 1) * dgoal],
        }
    }

    /// `size` relabelled transitions; rewards come from the goal's reward function.
    pub fn sample(&self, size: usize, rng: &mut ChaCha8Rng) -> Batch {
        let Dims {
            observation: dobs,
            goal: dgoal,
            action: dact,
        } = self.dims;
        let mut batch = Batch {
            len: size,
            ..Batch::default()
        };
        for _ in 0..size {
            let (episode, t, future) = self.draw(rng);
            let goal = self.goal_of(episode, t, future);
            let achieved_next = &episode.achieved_goal[(t + 1) * dgoal..(t + 2) * dgoal];
            batch
                .reward
                .push(self.goal.compute_reward(achieved_next, goal) as f32);
            batch
                .observation
                .extend_from_slice(&episode.observation[t * dobs..(t + 1) * dobs]);
            batch
                .next_observation
                .extend_from_slice(&episode.observation[(t + 1) * dobs..(t + 2) * dobs]);
            batch.goal.extend_from_slice(goal);
            batch
                .action
                .extend_from_slice(&episode.action[t * dact..(t + 1) * dact]);
            let last = t + 1 == episode.len;
            batch
                .terminal
                .push(if episode.terminated && last { 1.0 } else { 0.0 });
        }
        batch
    }

    /// Observations and relabelled goals from one episode, as HER baselines feed its
    /// normalisers: `count` draws with the same relabelling as training batches.
    pub fn normalizer_rows<'e>(
        &self,
        episode: &'e Episode,
        count: usize,
        rng: &mut ChaCha8Rng,
    ) -> Vec<(&'e [f64], &'e [f64])> {
        let dobs = self.dims.observation;
        (0..count)
            .map(|_| {
                let t = rng.random_range(0..episode.len);
                let future = self.relabel(episode, t, rng);
                (
                    &episode.observation[t * dobs..(t + 1) * dobs],
                    self.goal_of(episode, t, future),
                )
            })
            .collect()
    }
}

/// Where a buffer stands: what it must be restored to, beside its episodes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ReplayPosition {
    /// Episodes stored over its life, those that have left included.
    pub stored: usize,
    /// How many of the latest it holds.
    pub held: usize,
    /// Its longest episode ever stored.
    pub longest: usize,
}

/// The first bytes of a file of episodes.
const EPISODES_MAGIC: &[u8; 8] = b"DXEPIS01";

/// Episodes of environments of `dims` as bytes, exactly, written one at a time as they are
/// stored: a header, their count, then each episode's length, whether it ended in an absorbing
/// failure, and its rows (little-endian `f64` observations and goals, `f32` actions).
pub struct EpisodeFile {
    dims: Dims,
    count: usize,
    body: Vec<u8>,
}

impl EpisodeFile {
    pub fn new(dims: Dims) -> EpisodeFile {
        EpisodeFile {
            dims,
            count: 0,
            body: Vec::new(),
        }
    }

    pub fn push(&mut self, e: &Episode) {
        self.count += 1;
        self.body.extend((e.len as u64).to_le_bytes());
        self.body.push(e.terminated as u8);
        for values in [&e.observation, &e.achieved_goal, &e.desired_goal] {
            values
                .iter()
                .for_each(|v| self.body.extend(v.to_le_bytes()));
        }
        e.action
            .iter()
            .for_each(|v| self.body.extend(v.to_le_bytes()));
    }

    /// The file's bytes, which [`episodes_from_bytes`] reads back.
    pub fn into_bytes(self) -> Vec<u8> {
        let d = self.dims;
        let mut out = EPISODES_MAGIC.to_vec();
        for size in [d.observation, d.goal, d.action, self.count] {
            out.extend((size as u64).to_le_bytes());
        }
        out.extend(self.body);
        out
    }
}

/// Reads a byte string front to back, saying where it ends too soon.
struct Bytes<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Bytes<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let part = self
            .bytes
            .get(self.at..self.at + n)
            .ok_or_else(|| format!("it ends after {} bytes, cut short", self.bytes.len()))?;
        self.at += n;
        Ok(part)
    }

    fn word(&mut self) -> Result<usize, String> {
        let b = self.take(8)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")) as usize)
    }

    fn floats(&mut self, n: usize) -> Result<Vec<f64>, String> {
        Ok(self
            .take(n * 8)?
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect())
    }
}

/// The episodes an [`EpisodeFile`] wrote for environments of `dims`; says what is wrong
/// with bytes that are not such a file, are cut short, or were written for other sizes.
pub fn episodes_from_bytes(dims: Dims, bytes: &[u8]) -> Result<Vec<Episode>, String> {
    let mut input = Bytes { bytes, at: 0 };
    if input.take(EPISODES_MAGIC.len())? != EPISODES_MAGIC {
        return Err("it is not a file of episodes".into());
    }
    let sizes = [input.word()?, input.word()?, input.word()?];
    if sizes != [dims.observation, dims.goal, dims.action] {
        return Err(format!(
            "its episodes have observation, goal and action sizes {sizes:?}, this run's are \
             [{}, {}, {}]",
            dims.observation, dims.goal, dims.action
        ));
    }
    let count = input.word()?;
    let mut episodes = Vec::with_capacity(count.min(1 << 16));
    for _ in 0..count {
        let len = input.word()?;
        if len > 1 << 24 {
            return Err(format!(
                "it holds an episode of {len} steps, more than any run makes"
            ));
        }
        let terminated = input.take(1)?[0] != 0;
        let observation = input.floats((len + 1) * dims.observation)?;
        let achieved_goal = input.floats((len + 1) * dims.goal)?;
        let desired_goal = input.floats(len * dims.goal)?;
        let action = input
            .take(len * dims.action * 4)?
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect();
        episodes.push(Episode {
            len,
            observation,
            achieved_goal,
            desired_goal,
            action,
            terminated,
        });
    }
    if input.at != bytes.len() {
        return Err(format!(
            "{} bytes follow its last episode",
            bytes.len() - input.at
        ));
    }
    Ok(episodes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use dexcube_env::LayerGoal;
    use rand::SeedableRng;

    /// A one-dimensional episode whose achieved goal counts its steps.
    fn counting_episode(len: usize, desired: f64) -> Episode {
        Episode {
            len,
            observation: (0..=len).map(|t| t as f64).collect(),
            achieved_goal: (0..=len).map(|t| t as f64).collect(),
            desired_goal: vec![desired; len],
            action: vec![0.0; len],
            terminated: false,
        }
    }

    #[test]
    fn relabelled_goals_come_from_later_in_the_same_episode() {
        let dims = Dims {
            observation: 1,
            goal: 1,
            action: 1,
        };
        let mut buffer = HerBuffer::new(
            dims,
            1000,
            0.8,
            Arc::new(LayerGoal {
                angle_threshold: 0.5,
                ..LayerGoal::default()
            }),
        );
        buffer.store(counting_episode(10, 100.0));
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let batch = buffer.sample(2000, &mut rng);
        let relabelled = batch.goal.iter().filter(|&&g| g != 100.0).count() as f64 / 2000.0;
        assert!((relabelled - 0.8).abs() < 0.04, "{relabelled}");
        for i in 0..batch.len {
            let (o, g, r) = (batch.observation[i], batch.goal[i], batch.reward[i]);
            if g != 100.0 {
                assert!(g > o && g <= 10.0, "a future goal: step {o}, goal {g}");
            }
            // Success exactly when the next achieved goal (o + 1) is the goal.
            assert_eq!(r, if (o + 1.0 - g).abs() < 0.5 { 0.0 } else { -1.0 });
        }
        assert!(batch.reward.contains(&0.0), "hindsight makes successes");
        assert!(
            batch.terminal.iter().all(|&d| d == 0.0),
            "it ran its course"
        );
    }

    #[test]
    fn only_the_last_step_of_a_dropped_episode_is_terminal() {
        let dims = Dims {
            observation: 1,
            goal: 1,
            action: 1,
        };
        let mut buffer = HerBuffer::new(dims, 1000, 0.8, Arc::new(LayerGoal::default()));
        buffer.store(Episode {
            terminated: true,
            ..counting_episode(6, 100.0)
        });
        let batch = buffer.sample(600, &mut ChaCha8Rng::seed_from_u64(2));
        for i in 0..batch.len {
            let last = batch.next_observation[i] == 6.0;
            assert_eq!(batch.terminal[i], if last { 1.0 } else { 0.0 }, "row {i}");
        }
        assert!(batch.terminal.contains(&1.0));
    }

    #[test]
    fn without_her_goals_are_never_relabelled_and_old_episodes_leave() {
        let dims = Dims {
            observation: 1,
            goal: 1,
            action: 1,
        };
        let mut buffer = HerBuffer::new(dims, 25, 0.0, Arc::new(LayerGoal::default()));
        for _ in 0..3 {
            buffer.store(counting_episode(10, 100.0));
        }
        assert_eq!(buffer.transitions(), 20, "the oldest episode made room");
        let batch = buffer.sample(500, &mut ChaCha8Rng::seed_from_u64(1));
        assert!(batch.goal.iter().all(|&g| g == 100.0));
        assert!(batch.reward.iter().all(|&r| r == -1.0));
    }
}
