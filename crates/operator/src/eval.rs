//! The evaluation: Table I of the paper (success rate and action number by move distance,
//! with and without rollback) and the atomic actions on their own, each with the seeds and
//! counts that reproduce it.

use std::path::Path;

use burn::prelude::Device;
use dexcube_cube::Move;
use dexcube_env::{RecordedStart, RotGoal, RotMode};
use dexcube_rl::Policy;
use dexcube_rl::checkpoint::CheckpointError;
use dexcube_sim::{Scene, SceneKind, Sim};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::operator::{Operator, OperatorConfig, Planner, StageRecord, set_up_scramble};
use crate::stages::{
    Driving, PolicyStage1, PolicyStage2, RecordingStage1, RecordingStage2, Stage1, Stage2,
    pose_reached, trained_control_rate,
};

/// The paper's Table I, move distances 1 to 14.
pub const PAPER_SR_ROLLBACK: [f64; 14] = [
    1.0, 1.0, 0.95, 0.95, 0.89, 0.95, 0.94, 0.86, 0.85, 0.89, 0.8, 0.8, 0.88, 0.88,
];
pub const PAPER_SR_OPEN_LOOP: [f64; 14] = [
    0.93, 0.83, 0.82, 0.74, 0.72, 0.62, 0.46, 0.43, 0.42, 0.43, 0.34, 0.41, 0.37, 0.46,
];
pub const PAPER_AN_ROLLBACK: [f64; 14] = [
    4.8, 9.11, 11.49, 14.80, 18.04, 22.22, 26.87, 28.39, 34.91, 36.94, 41.0, 41.0, 41.81, 39.65,
];
pub const PAPER_AN_OPEN_LOOP: [f64; 14] = [
    4.81, 6.07, 9.90, 12.81, 15.22, 19.55, 21.57, 25.11, 26.06, 29.95, 34.2, 34.15, 34.65, 32.60,
];

/// Where the two policies are, and how Stage 1's pose is judged.
#[derive(Clone, Debug)]
pub struct PolicyFiles {
    pub rot: std::path::PathBuf,
    pub layer: std::path::PathBuf,
    pub rot_mode: RotMode,
}

/// Stage 1 and Stage 2 loaded from files, ready to drive one simulation, with the cube
/// scene's resting point (Stage 1's target position and the drop test's reference).
pub struct LoadedStages {
    pub stage1: PolicyStage1,
    pub stage2: PolicyStage2,
    pub resting: [f64; 3],
}

impl PolicyFiles {
    /// Loads both policies for a cube scene whose object rests at `resting`.
    pub fn load(&self, resting: [f64; 3]) -> Result<LoadedStages, CheckpointError> {
        let device = Device::flex();
        let (rot, layer) = (
            Policy::load(&self.rot, &device)?,
            Policy::load(&self.layer, &device)?,
        );
        Ok(LoadedStages {
            stage1: PolicyStage1 {
                goal: PolicyStage1::trained_goal(&rot, self.rot_mode, &self.rot)?,
                view: PolicyStage1::trained_view(&rot, &self.rot)?,
                control_rate: trained_control_rate(&rot, &self.rot)?,
                policy: rot,
                driving: Driving::default(),
            },
            stage2: PolicyStage2 {
                goal: PolicyStage2::trained_goal(&layer, &self.layer)?,
                view: PolicyStage2::trained_view(&layer, &self.layer)?,
                control_rate: trained_control_rate(&layer, &self.layer)?,
                policy: layer,
                resting_z: resting[2],
                driving: Driving::default(),
            },
            resting,
        })
    }
}

/// One cube of the evaluation, as a row of its CSV.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CubeResult {
    pub distance: usize,
    pub index: usize,
    pub rollback: bool,
    pub solved: bool,
    pub actions: usize,
    pub randomisations: usize,
    pub replans: usize,
    pub control_steps: usize,
    pub failure: String,
    /// How the stages fared; `None` in rows written before it was recorded.
    pub stages: Option<StageRecord>,
}

impl CubeResult {
    pub const CSV_HEADER: &'static str = "distance,index,rollback,solved,actions,randomisations,replans,control_steps,failure,stage1_runs,stage1_reached,stage2_runs,stage2_misaligned,stage1_turned";

    pub fn csv_row(&self) -> String {
        let stages = self.stages.map_or(",,,,".to_string(), |s| {
            format!(
                "{},{},{},{},{}",
                s.stage1_runs,
                s.stage1_reached,
                s.stage2_runs,
                s.stage2_misaligned,
                s.stage1_turned.map_or(String::new(), |n| n.to_string())
            )
        });
        format!(
            "{},{},{},{},{},{},{},{},{},{stages}",
            self.distance,
            self.index,
            self.rollback,
            self.solved,
            self.actions,
            self.randomisations,
            self.replans,
            self.control_steps,
            self.failure
        )
    }

    /// The stage whose run ended the attempt (the cube dropped or the physics blew up), from
    /// the failure text ("Dropped in Stage 1 at step 35").
    pub fn failed_stage(&self) -> Option<usize> {
        let (_, after) = self.failure.split_once(" in Stage ")?;
        after.split(' ').next()?.parse().ok()
    }

    /// A row of the CSV: 14 fields, the 13 of rows written before Stage 1's turned layers
    /// were counted, or the 9 of rows written before the stages were recorded.
    pub fn from_csv(line: &str) -> Option<CubeResult> {
        let f: Vec<&str> = line.trim().split(',').collect();
        let stages = match f.len() {
            9 => None,
            13 | 14 if f[9..].iter().all(|x| x.is_empty()) => None,
            13 | 14 => Some(StageRecord {
                stage1_runs: f[9].parse().ok()?,
                stage1_reached: f[10].parse().ok()?,
                stage2_runs: f[11].parse().ok()?,
                stage2_misaligned: f[12].parse().ok()?,
                stage1_turned: match f.get(13) {
                    None | Some(&"") => None,
                    Some(n) => Some(n.parse().ok()?),
                },
            }),
            _ => return None,
        };
        Some(CubeResult {
            stages,
            distance: f[0].parse().ok()?,
            index: f[1].parse().ok()?,
            rollback: f[2].parse().ok()?,
            solved: f[3].parse().ok()?,
            actions: f[4].parse().ok()?,
            randomisations: f[5].parse().ok()?,
            replans: f[6].parse().ok()?,
            control_steps: f[7].parse().ok()?,
            failure: f[8].to_string(),
        })
    }
}

/// Callbacks while a cube is solved: after every control step, and at every event; and
/// where to record each stage's starts, if anywhere ([`RecordingStage1`],
/// [`RecordingStage2`]).
pub struct Hooks<'a> {
    pub watch: &'a mut dyn FnMut(&mut Sim),
    pub narrate: &'a mut dyn FnMut(&crate::Event),
    pub stage1_starts: Option<&'a mut Vec<RecordedStart>>,
    pub stage2_starts: Option<&'a mut Vec<RecordedStart>>,
}

/// Solves one scrambled cube with the hand. The cube is made from `scramble` on the palm;
/// `seed` drives the rollback's randomisations.
pub fn run_cube(
    stages: &mut LoadedStages,
    scene: &std::sync::Arc<Scene>,
    planner: Planner,
    (scramble, config, seed): (&[Move], OperatorConfig, u64),
    hooks: Hooks,
) -> crate::Outcome {
    let mut sim = Sim::new(scene.clone());
    let resting = stages.resting;
    set_up_scramble(&mut sim, scramble, resting);
    // The rollback's check is the paper's pose test in the policy's mode.
    let accepts = pose_reached(RotGoal::paper(stages.stage1.goal.mode));
    stages.stage1.driving = config.driving;
    stages.stage2.driving = config.driving;
    let mut recording;
    let stage1: &mut dyn Stage1 = match hooks.stage1_starts {
        Some(starts) => {
            recording = RecordingStage1 {
                inner: &mut stages.stage1,
                starts,
                accepts: &accepts,
            };
            &mut recording
        }
        None => &mut stages.stage1,
    };
    let mut recording2;
    let stage2: &mut dyn Stage2 = match hooks.stage2_starts {
        Some(starts) => {
            recording2 = RecordingStage2 {
                inner: &mut stages.stage2,
                starts,
            };
            &mut recording2
        }
        None => &mut stages.stage2,
    };
    let mut operator = Operator {
        config,
        stage1,
        stage1_accepts: &accepts,
        stage2,
        planner,
        resting,
        rng: ChaCha8Rng::seed_from_u64(seed),
        watch: hooks.watch,
    };
    operator.solve(&mut sim, hooks.narrate)
}

/// The cube scene's resting point: where the cube settles on the palm, found as the
/// environments find theirs, so Stage 1's position target means the same in both.
pub fn resting_point() -> Result<[f64; 3], dexcube_sim::SimError> {
    Ok(dexcube_env::resting_point(&mut Sim::new(Scene::load(
        SceneKind::Cube,
    )?)))
}

/// One row of Table I.
#[derive(Clone, Debug, Serialize)]
pub struct TableRow {
    pub distance: usize,
    pub cubes_rollback: usize,
    pub sr_rollback: f64,
    pub an_rollback: f64,
    pub cubes_open_loop: usize,
    pub sr_open_loop: f64,
    pub an_open_loop: f64,
}

/// Success rate and mean action number (over all cubes, solved or not) per distance.
pub fn table(results: &[CubeResult], distances: &[usize]) -> Vec<TableRow> {
    let summary = |d: usize, rollback: bool| {
        let rows: Vec<&CubeResult> = results
            .iter()
            .filter(|r| r.distance == d && r.rollback == rollback)
            .collect();
        let n = rows.len();
        let sr = rows.iter().filter(|r| r.solved).count() as f64 / n.max(1) as f64;
        let an = rows.iter().map(|r| r.actions as f64).sum::<f64>() / n.max(1) as f64;
        (n, sr, an)
    };
    distances
        .iter()
        .map(|&d| {
            let (cubes_rollback, sr_rollback, an_rollback) = summary(d, true);
            let (cubes_open_loop, sr_open_loop, an_open_loop) = summary(d, false);
            TableRow {
                distance: d,
                cubes_rollback,
                sr_rollback,
                an_rollback,
                cubes_open_loop,
                sr_open_loop,
                an_open_loop,
            }
        })
        .collect()
}

/// Table I as markdown, ours beside the paper's, and how the stages fared in `results`.
pub fn markdown(rows: &[TableRow], results: &[CubeResult], command: &str) -> String {
    let cell = |n: usize, x: f64, digits: usize| {
        if n == 0 {
            "-".to_string()
        } else {
            format!("{x:.digits$}")
        }
    };
    let mut out = format!(
        "Produced by `{command}`.\n\n| move distance | cubes | SR rollback | SR rollback (paper) | AN rollback | AN rollback (paper) | SR open loop | SR open loop (paper) | AN open loop | AN open loop (paper) |\n|---|---|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows {
        let k = r.distance - 1;
        out += &format!(
            "| {} | {} | {} | {:.2} | {} | {:.2} | {} | {:.2} | {} | {:.2} |\n",
            r.distance,
            r.cubes_rollback.max(r.cubes_open_loop),
            cell(r.cubes_rollback, r.sr_rollback, 2),
            PAPER_SR_ROLLBACK[k],
            cell(r.cubes_rollback, r.an_rollback, 2),
            PAPER_AN_ROLLBACK[k],
            cell(r.cubes_open_loop, r.sr_open_loop, 2),
            PAPER_SR_OPEN_LOOP[k],
            cell(r.cubes_open_loop, r.an_open_loop, 2),
            PAPER_AN_OPEN_LOOP[k],
        );
    }
    out + &stages_markdown(results)
}

/// The atomic actions as they fared inside the attempts, for each variant, over the rows
/// that record them (none: an empty string): how often Stage 1 reached its pose and how often
/// it turned a layer (where every row counted that), how often Stage 2 left the cube out of
/// its good state, and how often each dropped the cube, as shares of their runs.
fn stages_markdown(results: &[CubeResult]) -> String {
    let mut out = String::new();
    for (variant, rollback) in [("with rollback", true), ("open loop", false)] {
        let rows: Vec<(&CubeResult, StageRecord)> = results
            .iter()
            .filter(|r| r.rollback == rollback)
            .filter_map(|r| Some((r, r.stages?)))
            .collect();
        if rows.is_empty() {
            continue;
        }
        let ended_by = |stage| {
            rows.iter()
                .filter(|(r, _)| r.failed_stage() == Some(stage))
                .count()
        };
        let sum = |f: fn(&StageRecord) -> usize| rows.iter().map(|(_, s)| f(s)).sum::<usize>();
        let (drops1, drops2) = (ended_by(1), ended_by(2));
        let runs1 = sum(|s| s.stage1_runs) + drops1;
        let runs2 = sum(|s| s.stage2_runs) + drops2;
        let share =
            |n: usize, of: usize| format!("{n} ({:.1}%)", 100.0 * n as f64 / of.max(1) as f64);
        let turned = rows
            .iter()
            .map(|(_, s)| s.stage1_turned)
            .sum::<Option<usize>>()
            .map_or("not counted".to_string(), |n| share(n, runs1));
        if out.is_empty() {
            out += "\nThe atomic actions inside the attempts (a run that dropped the cube or blew up the physics ended its attempt):\n\n| variant | cubes | Stage 1 runs | pose reached | layer turned | dropped | Stage 2 runs | cube left out of its good state | dropped |\n|---|---|---|---|---|---|---|---|---|\n";
        }
        out += &format!(
            "| {variant} | {} | {runs1} | {} | {turned} | {} | {runs2} | {} | {} |\n",
            rows.len(),
            share(sum(|s| s.stage1_reached), runs1),
            share(drops1, runs1),
            share(sum(|s| s.stage2_misaligned), runs2),
            share(drops2, runs2),
        );
    }
    out
}

/// Draws SR and AN against move distance, ours and the paper's, into PREFIX-sr.png and
/// PREFIX-an.png beside `path`.
pub fn plot(rows: &[TableRow], path: &Path) -> Result<(), String> {
    use dexcube_rl::plot::{Series, line_plot};
    type Measure = fn(&TableRow) -> f64;
    type Cubes = fn(&TableRow) -> usize;
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("table");
    // Ours (for distances with cubes) and the paper's, with rollback and open loop.
    let curves = |name: &str, ours: [Measure; 2], paper: [&[f64; 14]; 2]| -> Vec<Series> {
        let variants: [(&str, Cubes); 2] = [
            ("rollback", |r| r.cubes_rollback),
            ("open loop", |r| r.cubes_open_loop),
        ];
        variants
            .into_iter()
            .zip(ours.into_iter().zip(paper))
            .flat_map(|((variant, cubes), (ours, paper))| {
                [
                    Series {
                        label: format!("{name} {variant} (ours)"),
                        points: rows
                            .iter()
                            .filter(|r| cubes(r) > 0)
                            .map(|r| (r.distance as f64, ours(r)))
                            .collect(),
                        band: None,
                    },
                    Series {
                        label: format!("{name} {variant} (paper)"),
                        points: rows
                            .iter()
                            .map(|r| (r.distance as f64, paper[r.distance - 1]))
                            .collect(),
                        band: None,
                    },
                ]
            })
            .collect()
    };
    let sr = curves(
        "SR",
        [|r| r.sr_rollback, |r| r.sr_open_loop],
        [&PAPER_SR_ROLLBACK, &PAPER_SR_OPEN_LOOP],
    );
    line_plot(
        &path.with_file_name(format!("{stem}-sr.png")),
        "Success rate by move distance",
        "move distance",
        "success rate",
        1.05,
        &sr,
    )?;
    let an = curves(
        "AN",
        [|r| r.an_rollback, |r| r.an_open_loop],
        [&PAPER_AN_ROLLBACK, &PAPER_AN_OPEN_LOOP],
    );
    let an_max = rows
        .iter()
        .map(|r| r.an_rollback.max(r.an_open_loop))
        .fold(45.0, f64::max);
    line_plot(
        &path.with_file_name(format!("{stem}-an.png")),
        "Action number by move distance",
        "move distance",
        "atomic actions",
        an_max * 1.05,
        &an,
    )
}

/// The 95% Wilson score interval of a success rate.
pub fn wilson_interval(successes: usize, trials: usize) -> (f64, f64) {
    if trials == 0 {
        return (0.0, 1.0);
    }
    let (n, p, z) = (trials as f64, successes as f64 / trials as f64, 1.959_964);
    let centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
    let half = z / (1.0 + z * z / n) * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt();
    (centre - half, centre + half)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wilson_interval_matches_known_values() {
        let (lo, hi) = wilson_interval(952, 1000);
        assert!(
            (lo - 0.9372).abs() < 1e-3 && (hi - 0.9636).abs() < 1e-3,
            "{lo} {hi}"
        );
        assert_eq!(wilson_interval(0, 0), (0.0, 1.0));
    }

    #[test]
    fn table_aggregates_by_distance_and_variant() {
        let r = |d, rollback, solved, actions| CubeResult {
            distance: d,
            index: 0,
            rollback,
            solved,
            actions,
            randomisations: 0,
            replans: 0,
            control_steps: 0,
            failure: String::new(),
            stages: None,
        };
        let rows = table(
            &[
                r(1, true, true, 2),
                r(1, true, false, 6),
                r(1, false, true, 2),
            ],
            &[1, 2],
        );
        assert_eq!(
            (
                rows[0].cubes_rollback,
                rows[0].sr_rollback,
                rows[0].an_rollback
            ),
            (2, 0.5, 4.0)
        );
        assert_eq!((rows[0].cubes_open_loop, rows[0].sr_open_loop), (1, 1.0));
        assert_eq!(rows[1].cubes_rollback, 0);
        let line = r(3, false, true, 9).csv_row();
        assert_eq!(CubeResult::from_csv(&line), Some(r(3, false, true, 9)));
    }

    /// Rows record how the stages fared, rows from before that (or from before Stage 1's
    /// turned layers were counted) still read, and the table sums the stages over the rows
    /// that have them, and the turned layers only where every row counted them.
    #[test]
    fn stage_records_round_trip_and_are_summed() {
        let old = "2,7,true,false,5,1,0,518,Dropped";
        let row = CubeResult::from_csv(old).unwrap();
        assert_eq!((row.stages, row.failed_stage()), (None, None));
        assert_eq!(CubeResult::from_csv(&row.csv_row()), Some(row.clone()));
        let recorded = CubeResult {
            failure: "Dropped in Stage 1 at step 35".to_string(),
            stages: Some(StageRecord {
                stage1_runs: 3,
                stage1_reached: 2,
                stage2_runs: 4,
                stage2_misaligned: 1,
                stage1_turned: Some(1),
            }),
            ..row.clone()
        };
        assert_eq!(recorded.failed_stage(), Some(1));
        assert_eq!(
            CubeResult::from_csv(&recorded.csv_row()),
            Some(recorded.clone())
        );
        let solved = CubeResult {
            solved: true,
            failure: String::new(),
            ..recorded.clone()
        };
        let text = stages_markdown(&[row, recorded.clone(), solved.clone()]);
        assert!(
            text.contains(
                "| with rollback | 2 | 7 | 4 (57.1%) | 2 (28.6%) | 1 (14.3%) | 8 | 2 (25.0%) | 0 (0.0%) |"
            ),
            "{text}"
        );
        let uncounted = CubeResult::from_csv("2,7,true,true,5,1,0,518,,3,2,4,1").unwrap();
        assert_eq!(uncounted.stages.unwrap().stage1_turned, None);
        assert_eq!(
            CubeResult::from_csv(&uncounted.csv_row()),
            Some(uncounted.clone())
        );
        let text = stages_markdown(&[recorded, uncounted]);
        assert!(text.contains("| 4 (57.1%) | not counted |"), "{text}");
        assert!(!text.contains("open loop"));
        assert_eq!(stages_markdown(&[]), "");
    }
}
