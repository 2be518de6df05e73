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
    /// inputs keep their means and spreads but count as `rows` rows only, so that fresh rows
    /// soon outweigh the zeros the new inputs start from.
    pub fn widened(&self, extra: usize, rows: f64) -> Normalizer {
        let scale = if self.count > 0.0 {
            rows / self.count
        } else {
            0.0
        };
        let rescaled = |values: &[f64]| -> Vec<f64> {
            let mut out: Vec<f64> = values.iter().map(|v| v * scale).collect();
            out.resize(values.len() + extra, 0.0);
            out
        };
        Normalizer {
            sum: rescaled(&self.sum),
            sum_sq: rescaled(&self.sum_sq),
            count: self.count * scale,
            ..self.clone()
        }
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
    fn a_widened_normaliser_keeps_the_old_inputs_and_learns_the_new_one_from_fresh_rows() {
        let mut n = Normalizer::new(1, 0.01, 5.0, 200.0);
        for x in [1.0, 2.0, 3.0, 4.0] {
            n.update(&[x]);
        }
        let mut wide = n.widened(1, 2.0);
        assert_eq!(wide.size(), 2);
        assert!((wide.mean(0) - n.mean(0)).abs() < 1e-12);
        assert!((wide.std(0) - n.std(0)).abs() < 1e-12);
        for _ in 0..2 {
            wide.update(&[2.5, 0.3]);
        }
        assert!(
            (wide.mean(0) - 2.5).abs() < 1e-12,
            "the old input's mean stands"
        );
        assert!(
            (wide.mean(1) - 0.15).abs() < 1e-12,
            "the new input starts from zeros weighing as much as the kept rows"
        );
    }
}
