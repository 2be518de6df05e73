//! Learning curves across seeds: the test success of runs that differ only in their seed,
//! as a mean with a band of one standard deviation, the form of the paper's training-curve
//! figures. Runs are grouped by their label (environment, mode, object, move) and algorithm
//! (DDPG or TD3), so one call can draw the paper's comparison of the six Stage 2 moves, a
//! curve per move, or DDPG's curve beside TD3's.

use std::path::{Path, PathBuf};

use crate::checkpoint;
use crate::plot::{Series, line_plot};
use crate::train::{EpochMetrics, RunCurve, TrainError};

/// One label's curve across its seeds: per epoch, (training episodes, mean test success,
/// standard deviation across seeds).
pub struct SeedCurve {
    pub label: String,
    pub seeds: Vec<u64>,
    pub points: Vec<(f64, f64, f64)>,
}

/// Mean and standard deviation (over seeds, dividing by their number) of the test success at
/// each epoch that every run has reached. The runs must count episodes alike.
pub fn across_seeds(runs: &[&[EpochMetrics]]) -> Result<Vec<(f64, f64, f64)>, String> {
    let epochs = runs.iter().map(|m| m.len()).min().unwrap_or(0);
    (0..epochs)
        .map(|e| {
            let episodes = runs[0][e].episodes;
            if runs.iter().any(|m| m[e].episodes != episodes) {
                return Err(format!(
                    "the runs count different episodes by epoch {e}: train them with the same \
                     --envs and schedule"
                ));
            }
            let n = runs.len() as f64;
            let mean = runs.iter().map(|m| m[e].test_success).sum::<f64>() / n;
            let variance = runs
                .iter()
                .map(|m| (m[e].test_success - mean).powi(2))
                .sum::<f64>()
                / n;
            Ok((episodes as f64, mean, variance.sqrt()))
        })
        .collect()
}

/// Groups the runs in `dirs` by label (and algorithm: DDPG or TD3), in the order each label
/// first appears, and averages
/// each group across its seeds. Two runs of one label with the same seed, or with different
/// hyperparameters, are refused.
pub fn seed_curves(dirs: &[PathBuf]) -> Result<Vec<SeedCurve>, TrainError> {
    let mut groups: Vec<Vec<(&PathBuf, RunCurve)>> = Vec::new();
    for dir in dirs {
        let mut run = RunCurve::read(dir)?;
        if run.config.twin_critics {
            // TD3's runs are their own curve beside DDPG's of the same environment.
            run.label.push_str(" (TD3)");
        }
        let Some(members) = groups.iter_mut().find(|g| g[0].1.label == run.label) else {
            groups.push(vec![(dir, run)]);
            continue;
        };
        if let Some((twin, _)) = members.iter().find(|(_, m)| m.seed == run.seed) {
            return Err(TrainError::Plot(format!(
                "{} and {} are both seed {} of {}: pass each seed once",
                twin.display(),
                dir.display(),
                run.seed,
                run.label
            )));
        }
        let (first, kin) = &members[0];
        if kin.config != run.config {
            return Err(TrainError::Plot(format!(
                "{} and {} are runs of {} with different hyperparameters, not seeds of \
                 one experiment: draw them in separate figures",
                first.display(),
                dir.display(),
                run.label
            )));
        }
        members.push((dir, run));
    }
    groups
        .into_iter()
        .map(|members| {
            let metrics: Vec<&[EpochMetrics]> =
                members.iter().map(|(_, m)| m.metrics.as_slice()).collect();
            let label = members[0].1.label.clone();
            let points = across_seeds(&metrics)
                .map_err(|message| TrainError::Plot(format!("{label}: {message}")))?;
            Ok(SeedCurve {
                seeds: members.iter().map(|(_, m)| m.seed).collect(),
                label,
                points,
            })
        })
        .collect()
}

/// Writes `out` (a PNG: each label's mean test success against training episodes, with a band
/// of one standard deviation) and the same figures as CSV beside it (`out` with `.csv`).
pub fn plot_seed_curves(curves: &[SeedCurve], out: &Path) -> Result<PathBuf, TrainError> {
    let mut csv = String::from("label,seeds,episodes,mean_test_success,std_test_success\n");
    for curve in curves {
        let seeds: Vec<String> = curve.seeds.iter().map(u64::to_string).collect();
        for (episodes, mean, std) in &curve.points {
            csv += &format!(
                "\"{}\",{},{episodes},{mean:.4},{std:.4}\n",
                curve.label,
                seeds.join(" ")
            );
        }
    }
    checkpoint::write_atomically(&out.with_extension("csv"), csv.as_bytes())?;
    let series: Vec<Series> = curves
        .iter()
        .map(|curve| Series {
            label: {
                let n = curve.seeds.len();
                format!(
                    "{} ({n} seed{})",
                    curve.label,
                    if n == 1 { "" } else { "s" }
                )
            },
            points: curve.points.iter().map(|&(x, mean, _)| (x, mean)).collect(),
            band: Some(
                curve
                    .points
                    .iter()
                    .map(|&(x, mean, std)| (x, (mean - std).max(0.0), (mean + std).min(1.0)))
                    .collect(),
            ),
        })
        .collect();
    line_plot(
        out,
        "test success, mean ± one standard deviation across seeds",
        "training episodes",
        "test success rate",
        1.0,
        &series,
    )
    .map_err(TrainError::Plot)?;
    Ok(out.to_path_buf())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(successes: &[f64], episodes_per_epoch: usize) -> Vec<EpochMetrics> {
        successes
            .iter()
            .enumerate()
            .map(|(epoch, &test_success)| EpochMetrics {
                epoch,
                episodes: (epoch + 1) * episodes_per_epoch,
                test_success,
                ..EpochMetrics::default()
            })
            .collect()
    }

    #[test]
    fn seeds_are_averaged_over_the_epochs_every_run_reached() {
        let (a, b, c) = (
            run(&[0.0, 0.5, 1.0], 200),
            run(&[0.2, 0.7], 200),
            run(&[0.4, 0.9, 0.9, 0.9], 200),
        );
        let points = across_seeds(&[&a, &b, &c]).unwrap();
        assert_eq!(points.len(), 2);
        let (episodes, mean, std) = points[1];
        assert_eq!(episodes, 400.0);
        assert!((mean - 0.7).abs() < 1e-12);
        // Deviations -0.2, 0, 0.2: population variance 0.08 / 3.
        assert!((std - (0.08f64 / 3.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn runs_that_count_episodes_differently_are_refused() {
        let (a, b) = (run(&[0.1, 0.2], 200), run(&[0.1, 0.2], 400));
        let message = across_seeds(&[&a, &b]).unwrap_err();
        assert!(message.contains("different episodes"), "{message}");
    }
}
