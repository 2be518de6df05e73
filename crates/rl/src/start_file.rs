//! Recorded starts of a stage ([`RecordedStart`]) on disk: one safetensors file of float64
//! tensors, `state` (starts × state size), `goal` (starts × goal size: 7 for Stage 1's pose,
//! 2 for Stage 2's angle and the angle already turned) and `failed` (starts), with the
//! stage, what `failed` marks, the scene and the command that recorded them in its metadata.
//! Written atomically, and checked on loading, like a checkpoint. Files from before Stage 2
//! starts (sessions 13 to 18) name the goal `pose_goal` and the failures `dropped`, hold
//! Stage 1's, and are read as such; files without a `failure` entry (before session 20) mark
//! Stage 1's drops only.

use std::collections::HashMap;
use std::path::Path;

use dexcube_env::{RecordedFailure, RecordedStart};
use safetensors::tensor::Dtype;

use crate::checkpoint::{CheckpointError, RawTensor, write_safetensors};

/// What a file of starts says about where they came from.
#[derive(Clone, Debug, PartialEq)]
pub struct StartsOrigin {
    /// The stage whose starts they are: "rot" (Stage 1) or "layer" (Stage 2).
    pub stage: String,
    /// What a start's `failed` mark means.
    pub failure: RecordedFailure,
    /// The scene the states belong to ("cube").
    pub scene: String,
    /// The command that recorded them.
    pub command: String,
}

/// Writes `starts` (all of one state size and one goal size) with their origin.
pub fn save_starts(
    path: &Path,
    starts: &[RecordedStart],
    origin: &StartsOrigin,
) -> Result<(), CheckpointError> {
    let size = starts.first().map_or(0, |s| s.state.len());
    let goal_size = starts.first().map_or(0, |s| s.goal.len());
    if starts
        .iter()
        .any(|s| s.state.len() != size || s.goal.len() != goal_size)
    {
        return Err(CheckpointError::Io {
            path: path.to_path_buf(),
            message: "the starts differ in size".into(),
        });
    }
    let n = starts.len();
    let tensor = |name: &str, shape: Vec<usize>, values: Vec<f64>| RawTensor {
        name: name.to_string(),
        dtype: Dtype::F64,
        shape,
        data: values.into_iter().flat_map(f64::to_le_bytes).collect(),
    };
    let tensors = [
        tensor(
            "state",
            vec![n, size],
            starts
                .iter()
                .flat_map(|s| s.state.iter().copied())
                .collect(),
        ),
        tensor(
            "goal",
            vec![n, goal_size],
            starts.iter().flat_map(|s| s.goal.iter().copied()).collect(),
        ),
        tensor(
            "failed",
            vec![n],
            starts
                .iter()
                .map(|s| f64::from(u8::from(s.failed)))
                .collect(),
        ),
    ];
    let metadata = HashMap::from([
        ("stage".to_string(), origin.stage.clone()),
        ("failure".to_string(), origin.failure.tag().to_string()),
        ("scene".to_string(), origin.scene.clone()),
        ("command".to_string(), origin.command.clone()),
    ]);
    write_safetensors(path, &tensors, Some(metadata))
}

/// Reads a file written by [`save_starts`], checking its tensors' names, types and shapes.
pub fn load_starts(path: &Path) -> Result<(Vec<RecordedStart>, StartsOrigin), CheckpointError> {
    let bytes = std::fs::read(path).map_err(|e| CheckpointError::Io {
        path: path.to_path_buf(),
        message: format!(
            "{e} (record starts with `dexcube eval ... --record-starts {}`, or \
             `--record-layer-starts` for Stage 2's)",
            path.display()
        ),
    })?;
    let corrupt = |message: String| CheckpointError::Corrupt {
        path: path.to_path_buf(),
        message,
    };
    let (_, header) =
        safetensors::SafeTensors::read_metadata(&bytes).map_err(|e| corrupt(e.to_string()))?;
    let file = safetensors::SafeTensors::deserialize(&bytes).map_err(|e| corrupt(e.to_string()))?;
    let tensor = |name: &str| -> Result<(Vec<usize>, Vec<f64>), CheckpointError> {
        let view = file
            .tensor(name)
            .map_err(|_| corrupt(format!("no tensor '{name}': not a file of recorded starts")))?;
        if view.dtype() != Dtype::F64 {
            return Err(corrupt(format!("tensor '{name}' is not F64")));
        }
        let values = view
            .data()
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
            .collect();
        Ok((view.shape().to_vec(), values))
    };
    let (state_shape, states) = tensor("state")?;
    let legacy = file.tensor("goal").is_err();
    let (goal_shape, goals) = tensor(if legacy { "pose_goal" } else { "goal" })?;
    let (failed_shape, failed) = tensor(if legacy { "dropped" } else { "failed" })?;
    let (&[n, size], &[goal_n, goal_size]) = (&state_shape[..], &goal_shape[..]) else {
        return Err(corrupt(format!(
            "'state' has shape {state_shape:?} and 'goal' {goal_shape:?}"
        )));
    };
    if goal_n != n || failed_shape != [n] || (size == 0 && n > 0) {
        return Err(corrupt(format!(
            "shapes {state_shape:?}, {goal_shape:?} and {failed_shape:?} do not agree"
        )));
    }
    let metadata = header.metadata().clone().unwrap_or_default();
    let field = |key: &str| metadata.get(key).cloned().unwrap_or_default();
    let stage = metadata
        .get("stage")
        .cloned()
        .unwrap_or_else(|| "rot".into());
    let failure = match metadata.get("failure") {
        Some(tag) => RecordedFailure::from_tag(tag)
            .ok_or_else(|| corrupt(format!("unknown failure mark '{tag}' in its metadata")))?,
        None if stage == "rot" => RecordedFailure::Dropped,
        None => RecordedFailure::NotSquare,
    };
    let origin = StartsOrigin {
        stage,
        failure,
        scene: field("scene"),
        command: field("command"),
    };
    let starts = (0..n)
        .map(|k| RecordedStart {
            state: states[k * size..(k + 1) * size].to_vec(),
            goal: goals[k * goal_size..(k + 1) * goal_size].to_vec(),
            failed: failed[k] != 0.0,
        })
        .collect();
    Ok((starts, origin))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn starts_round_trip_and_a_damaged_file_is_refused() {
        let dir = std::env::temp_dir().join(format!("dexcube-starts-{}", std::process::id()));
        let path = dir.join("starts.safetensors");
        let starts: Vec<RecordedStart> = (0..3)
            .map(|k| RecordedStart {
                state: vec![k as f64, 0.5, -1e-9],
                goal: vec![0.1 * k as f64; 7],
                failed: k == 1,
            })
            .collect();
        let origin = StartsOrigin {
            stage: "rot".into(),
            failure: RecordedFailure::DroppedOrMissed,
            scene: "cube".into(),
            command: "dexcube eval --record-starts x".into(),
        };
        save_starts(&path, &starts, &origin).expect("saved");
        assert_eq!(
            load_starts(&path).expect("loaded"),
            (starts.clone(), origin.clone())
        );

        let bytes = std::fs::read(&path).expect("read");
        std::fs::write(&path, &bytes[..bytes.len() - 8]).expect("truncated");
        let error = load_starts(&path).expect_err("a truncated file");
        assert!(matches!(error, CheckpointError::Corrupt { .. }), "{error}");

        let mut uneven = starts;
        uneven[2].state.pop();
        assert!(save_starts(&path, &uneven, &origin).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }

    /// The files sessions 13 to 18 recorded (goal named `pose_goal`, failures `dropped`, no
    /// stage) read as Stage 1's, with their drops as the failures; session 19's, with a stage
    /// but no failure mark, read as marking drops for Stage 1 and the square test for Stage 2.
    #[test]
    fn a_file_from_before_stage_2_starts_reads_as_stage_1s() {
        let committed = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../results/starts/starts-select-seed2.safetensors"
        );
        let (starts, origin) = load_starts(Path::new(committed)).expect("loaded");
        assert_eq!(origin.stage, "rot");
        assert_eq!(origin.failure, RecordedFailure::Dropped);
        assert_eq!(origin.scene, "cube");
        assert_eq!(starts.len(), 1254);
        assert!(starts.iter().all(|s| s.goal.len() == 7));
        // The policy that recorded them (session 13's Stage 1) dropped the cube from 19.
        assert_eq!(starts.iter().filter(|s| s.failed).count(), 19);

        let session_19 = |name: &str| {
            let path = format!("{}/../../results/starts/{name}", env!("CARGO_MANIFEST_DIR"));
            let (starts, origin) = load_starts(Path::new(&path)).expect("loaded");
            let failed = starts.iter().filter(|s| s.failed).count();
            (origin.stage, origin.failure, starts.len(), failed)
        };
        assert_eq!(
            session_19("starts2-select-seed2.safetensors"),
            ("rot".into(), RecordedFailure::Dropped, 1200, 6)
        );
        assert_eq!(
            session_19("layer-starts-select-seed2.safetensors"),
            ("layer".into(), RecordedFailure::NotSquare, 1854, 124)
        );
    }
}
