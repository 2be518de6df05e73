//! Episode starts recorded where the operator began Stage 1: the physics state once the hand
//! has opened from where the last stage left it and the policy takes over, and the pose the
//! operator asked for. CubeRotEnv can reset from them ([`CubeRotEnv::with_starts`],
//! [`CubeRotEnv::reset_from`]), so that training and `eval-stage` see the states the
//! operator hands Stage 1, not only a cube freshly set down on a flat hand: session 12 found
//! that the second understates how often a policy drops the cube in the operator threefold.
//!
//! [`CubeRotEnv::with_starts`]: crate::CubeRotEnv::with_starts
//! [`CubeRotEnv::reset_from`]: crate::CubeRotEnv::reset_from

use std::sync::Arc;

/// One recorded start of Stage 1.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordedStart {
    /// The physics state when the policy took over (`Sim::physics_state`).
    pub state: Vec<f64>,
    /// The pose asked for: position, then quaternion (CubeRotEnv's 7-number pose goal).
    pub pose_goal: Vec<f64>,
    /// Whether the policy that was recorded went on to drop the cube from here.
    pub dropped: bool,
}

/// Recorded starts, and which of a CubeRotEnv's resets begin from them.
#[derive(Clone, Debug)]
pub struct StartMix {
    pub starts: Arc<[RecordedStart]>,
    pub pick: StartPick,
}

/// How a reset picks a recorded start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StartPick {
    /// Training: with probability `share` a reset begins from a recorded start, and
    /// otherwise from the usual fresh placement. A start the recorded policy dropped the cube
    /// from is drawn `dropped_weight` times as often as one it kept the cube from (1: all
    /// alike), so that training can spend more of its episodes where drops begin.
    Share { share: f64, dropped_weight: f64 },
    /// Evaluation: a reset with seed k begins from start k (modulo their number), so that
    /// episodes 0 to n - 1 visit each start once.
    Numbered,
}

/// The start a draw `u`, uniform in [0, 1), picks when each start the recorded policy dropped
/// the cube from weighs `dropped_weight` and each other start 1.
pub(crate) fn weighted_start(starts: &[RecordedStart], dropped_weight: f64, u: f64) -> usize {
    let weight = |start: &RecordedStart| if start.dropped { dropped_weight } else { 1.0 };
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

    /// A dropped start of weight 2 between two kept ones takes half of the draws, the middle
    /// half; weight 1 gives each a third.
    #[test]
    fn a_dropped_start_is_drawn_in_proportion_to_its_weight() {
        let start = |dropped| RecordedStart {
            state: vec![],
            pose_goal: vec![],
            dropped,
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
