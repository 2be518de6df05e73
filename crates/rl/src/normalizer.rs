//! Running mean and standard deviation of observations and goals, as HER baselines keep them:
//! inputs are clipped to ±`clip_obs`, centred, divided by max(std, eps) and clipped to ±`clip`.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Normalizer {
    sum: Vec<f64>,
    sum_sq: Vec<f64>,
    count: f64,
    eps: f64,
    clip: f64,
    clip_input: f64,
}

impl Normalizer {
    pub fn new(size: usize, eps: f64, clip: f64, clip_input: f64) -> Normalizer {
        Normalizer {
            sum: vec![0.0; size],
            sum_sq: vec![0.0; size],
            count: 0.0,
            eps,
            clip,
            clip_input,
        }
    }

    pub fn size(&self) -> usize {
        self.sum.len()
    }

    /// Adds one row to the statistics.
    pub fn update(&mut self, row: &[f64]) {
        for (k, &x) in row.iter().enumerate() {
            let x = x.clamp(-self.clip_input, self.clip_input);
            self.sum[k] += x;
            self.sum_sq[k] += x * x;
        }
        self.count += 1.0;
    }

    pub fn mean(&self, k: usize) -> f64 {
        if self.count == 0.0 {
            0.0
        } else {
            self.sum[k] / self.count
        }
    }

    pub fn std(&self, k: usize) -> f64 {
        if self.count == 0.0 {
            return 1.0;
        }
        let variance = self.sum_sq[k] / self.count - self.mean(k).powi(2);
        variance.max(self.eps * self.eps).sqrt()
    }

    /// The same statistics with `extra` inputs appended that have no history yet. The old
    /// inputs keep every row they were learnt from: a trained policy's behaviour rests on
    /// them, and refitting them to a new run's first rows moves its inputs (measured: Stage
    /// 1's goal means moved by up to a quarter of a spread, and its success on the cube fell
    /// from 87 to 34 of 100). The new inputs start at mean 0 and spread 1, so they are fed as
    /// they are, and fresh rows move them only as fast as the old inputs' statistics.
    pub fn widened(&self, extra: usize) -> Normalizer {
        let appended = |values: &[f64], fill: f64| -> Vec<f64> {
            let mut out = values.to_vec();
            out.resize(values.len() + extra, fill);
            out
        };
        Normalizer {
            sum: appended(&self.sum, 0.0),
            sum_sq: appended(&self.sum_sq, self.count),
            ..self.clone()
        }
    }

    /// The statistics of every row that `normalizers` learnt from, taken together: the inputs a
    /// weight average of their policies will see. `None` if they differ in size or settings.
    pub fn pooled(normalizers: &[&Normalizer]) -> Option<Normalizer> {
        let (first, rest) = normalizers.split_first()?;
        let mut pooled = (*first).clone();
        for other in rest {
            let same_settings = (other.eps, other.clip, other.clip_input)
                == (pooled.eps, pooled.clip, pooled.clip_input);
            if other.size() != pooled.size() || !same_settings {
                return None;
            }
            for k in 0..pooled.size() {
                pooled.sum[k] += other.sum[k];
                pooled.sum_sq[k] += other.sum_sq[k];
            }
            pooled.count += other.count;
        }
        Some(pooled)
    }

    /// Appends the normalised `row` to `out`.
    pub fn normalize_into(&self, row: &[f64], out: &mut Vec<f32>) {
        for (k, &x) in row.iter().enumerate() {
            let x = x.clamp(-self.clip_input, self.clip_input);
            out.push(((x - self.mean(k)) / self.std(k)).clamp(-self.clip, self.clip) as f32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standardises_and_clips() {
        let mut n = Normalizer::new(2, 0.01, 5.0, 200.0);
        for x in [1.0, 2.0, 3.0] {
            n.update(&[x, 7.0]);
        }
        assert!((n.mean(0) - 2.0).abs() < 1e-12);
        assert!((n.std(0) - (2.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!(n.std(1), 0.01, "a constant input divides by eps");
        let mut out = vec![];
        n.normalize_into(&[2.0, 1000.0], &mut out);
        assert_eq!(out, [0.0, 5.0]);
    }

    #[test]
    fn pooled_statistics_are_those_of_all_the_rows_together() {
        let mut a = Normalizer::new(1, 0.01, 5.0, 200.0);
        let mut b = a.clone();
        let mut both = a.clone();
        for x in [1.0, 2.0] {
            a.update(&[x]);
            both.update(&[x]);
        }
        for x in [6.0, 7.0, 9.0] {
            b.update(&[x]);
            both.update(&[x]);
        }
        let pooled = Normalizer::pooled(&[&a, &b]).unwrap();
        assert!((pooled.mean(0) - both.mean(0)).abs() < 1e-12);
        assert!((pooled.std(0) - both.std(0)).abs() < 1e-12);
        assert_eq!(
            Normalizer::pooled(&[&a, &a.widened(1)]),
            None,
            "sizes differ"
        );
        assert_eq!(Normalizer::pooled(&[]), None);
    }

    #[test]
    fn a_widened_normaliser_keeps_the_old_inputs_and_feeds_the_new_one_as_it_is() {
        let mut n = Normalizer::new(1, 0.01, 5.0, 200.0);
        for x in [1.0, 2.0, 3.0, 4.0] {
            n.update(&[x]);
        }
        let mut wide = n.widened(1);
        assert_eq!(wide.size(), 2);
        assert!((wide.mean(0) - n.mean(0)).abs() < 1e-12);
        assert!((wide.std(0) - n.std(0)).abs() < 1e-12);
        assert_eq!((wide.mean(1), wide.std(1)), (0.0, 1.0));
        let mut out = Vec::new();
        wide.normalize_into(&[2.5, 0.3], &mut out);
        assert!((out[1] - 0.3).abs() < 1e-6, "the new input as it is");
        wide.update(&[2.5, 0.3]);
        assert!(
            (wide.mean(0) - 2.5).abs() < 1e-12,
            "a fresh row weighs one of five on the old input"
        );
        assert!(
            (wide.mean(1) - 0.06).abs() < 1e-12,
            "and on the new one alike"
        );
    }
}
