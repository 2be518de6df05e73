//! Episode starts recorded where the operator began a stage: the physics state once the hand
//! has opened from where the last stage left it and the policy takes over, the goal it was
//! given, and whether the recorded policy failed from there. CubeRotEnv and LayerOpEnv can
//! reset from them (`with_starts`, `reset_from`), so that training and `eval-stage` see the
//! states the operator hands a stage, not only a cube freshly set down on a flat hand:
//! session 12 found that the second understates how often Stage 1 drops the cube in the
//! operator threefold.

use std::sync::Arc;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// One recorded start of a stage.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordedStart {
    /// The physics state when the policy took over (`Sim::physics_state`).
    pub state: Vec<f64>,
    /// The goal asked for: for Stage 1 the pose, position then quaternion (CubeRotEnv's
    /// 7-number pose goal); for Stage 2 the layer angle to turn (+π/2, U'), then the angle
    /// the layer had already turned when the policy took over, which its view counts from,
    /// then (since session 54) the face whose layer turns, its place in `Face::ALL`
    /// ([`CubeLayer::start_goal`](crate::CubeLayer::start_goal)).
    pub goal: Vec<f64>,
    /// Whether the policy that was recorded failed from here, in the way its file's
    /// [`RecordedFailure`] says.
    pub failed: bool,
}

/// What a file of recorded starts marks as a failure of the policy that was recorded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordedFailure {
    /// Stage 1 as recorded in sessions 13 to 19: the cube dropped (or the physics diverged).
    Dropped,
    /// Stage 1 since session 20: the cube dropped, or the stage ended without the pose the
    /// operator's check after Stage 1 accepts (the paper's pose test in the policy's mode).
    DroppedOrMissed,
    /// Stage 2: the layer not left turned within 0.1 rad of the quarter turn with the cube
    /// in its good state (or the cube dropped).
    NotSquare,
}

impl RecordedFailure {
    /// The name a start file's metadata gives it.
    pub fn tag(self) -> &'static str {
        match self {
            RecordedFailure::Dropped => "dropped",
            RecordedFailure::DroppedOrMissed => "dropped-or-missed",
            RecordedFailure::NotSquare => "not-square",
        }
    }

    /// The failure a tag names.
    pub fn from_tag(tag: &str) -> Option<RecordedFailure> {
        [
            RecordedFailure::Dropped,
            RecordedFailure::DroppedOrMissed,
            RecordedFailure::NotSquare,
        ]
        .into_iter()
        .find(|f| f.tag() == tag)
    }

    /// What the recorded policy did from a failed start, as a verb phrase.
    pub fn describe(self) -> &'static str {
        match self {
            RecordedFailure::Dropped => "dropped the cube",
            RecordedFailure::DroppedOrMissed => "dropped the cube or missed the pose",
            RecordedFailure::NotSquare => "did not leave the layer turned with the cube square",
        }
    }
}

/// Recorded starts, and which of an environment's resets begin from them.
#[derive(Clone, Debug)]
pub struct StartMix {
    pub starts: Arc<[RecordedStart]>,
    pub pick: StartPick,
}

/// How a reset picks a recorded start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StartPick {
    /// Training: with probability `share` a reset begins from a recorded start, and
    /// otherwise from the usual fresh placement. A start the recorded policy failed from is
    /// drawn `failed_weight` times as often as one it succeeded from (1: all alike), so
    /// that training can spend more of its episodes where failures begin.
    Share { share: f64, failed_weight: f64 },
    /// Evaluation: a reset with seed k begins from start k (modulo their number), so that
    /// episodes 0 to n - 1 visit each start once.
    Numbered,
}

impl StartMix {
    /// The start a reset with `seed` begins from, if any, drawing from `rng` as
    /// [`StartPick`] says; `None` for a fresh placement.
    pub(crate) fn pick(&self, seed: Option<u64>, rng: &mut ChaCha8Rng) -> Option<&RecordedStart> {
        let starts = &self.starts;
        if starts.is_empty() {
            return None;
        }
        let k = match (self.pick, seed) {
            (StartPick::Numbered, Some(seed)) => seed as usize % starts.len(),
            (StartPick::Share { share, .. }, _) if rng.random::<f64>() >= share => return None,
            // Weight 1 keeps the uniform draw, so runs from before the weight draw the same
            // starts when resumed.
            (StartPick::Share { failed_weight, .. }, _) if failed_weight != 1.0 => {
                weighted_start(starts, failed_weight, rng.random())
            }
            _ => rng.random_range(0..starts.len()),
        };
        Some(&starts[k])
    }
}

/// The start a draw `u`, uniform in [0, 1), picks when each start the recorded policy failed
/// from weighs `failed_weight` and each other start 1.
fn weighted_start(starts: &[RecordedStart], failed_weight: f64, u: f64) -> usize {
    let weight = |start: &RecordedStart| if start.failed { failed_weight } else { 1.0 };
    let total: f64 = starts.iter().map(weight).sum();
    let mut left = u * total;
    for (k, start) in starts.iter().enumerate() {
        left -= weight(start);
        if left < 0.0 {
            return k;
        }
    }
    starts.len() - 1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A failed start of weight 2 between two others takes half of the draws, the middle
    /// half; weight 1 gives each a third.
    #[test]
    fn a_failed_start_is_drawn_in_proportion_to_its_weight() {
        let start = |failed| RecordedStart {
            state: vec![],
            goal: vec![],
            failed,
        };
        let starts = [start(false), start(true), start(false)];
        let picks = |weight, draws: &[f64]| -> Vec<usize> {
            draws
                .iter()
                .map(|&u| weighted_start(&starts, weight, u))
                .collect()
        };
        let draws = [0.0, 0.24, 0.26, 0.5, 0.74, 0.76, 0.999];
        assert_eq!(picks(2.0, &draws), [0, 0, 1, 1, 1, 2, 2]);
        assert_eq!(picks(1.0, &draws), [0, 0, 0, 1, 2, 2, 2]);
    }
}
