//! Recorded Stage 1 starts ([`RecordedStart`]) on disk: one safetensors file of float64
//! tensors, `state` (starts × state size), `pose_goal` (starts × 7) and `dropped` (starts),
//! with the scene and the command that recorded them in its metadata. Written atomically, and
//! checked on loading, like a checkpoint.

use std::collections::HashMap;
use std::path::Path;

use dexcube_env::RecordedStart;
use safetensors::tensor::Dtype;

use crate::checkpoint::{CheckpointError, RawTensor, write_safetensors};

/// What a file of starts says about where they came from.
#[derive(Clone, Debug, PartialEq)]
pub struct StartsOrigin {
    /// The scene the states belong to ("cube").
    pub scene: String,
    /// The command that recorded them.
    pub command: String,
}

const POSE_GOAL: usize = 7;

/// Writes `starts` (all of one state size) with their origin.
pub fn save_starts(
    path: &Path,
    starts: &[RecordedStart],
    origin: &StartsOrigin,
) -> Result<(), CheckpointError> {
    let size = starts.first().map_or(0, |s| s.state.len());
    if starts
        .iter()
        .any(|s| s.state.len() != size || s.pose_goal.len() != POSE_GOAL)
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
            "pose_goal",
            vec![n, POSE_GOAL],
            starts
                .iter()
                .flat_map(|s| s.pose_goal.iter().copied())
                .collect(),
        ),
        tensor(
            "dropped",
            vec![n],
            starts
                .iter()
                .map(|s| f64::from(u8::from(s.dropped)))
                .collect(),
        ),
    ];
    let metadata = HashMap::from([
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
            "{e} (record starts with `dexcube eval ... --record-starts {}`)",
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
    let (goal_shape, goals) = tensor("pose_goal")?;
    let (dropped_shape, dropped) = tensor("dropped")?;
    let [n, size] = state_shape[..] else {
        return Err(corrupt(format!("'state' has shape {state_shape:?}")));
    };
    if goal_shape != [n, POSE_GOAL] || dropped_shape != [n] || (size == 0 && n > 0) {
        return Err(corrupt(format!(
            "shapes {state_shape:?}, {goal_shape:?} and {dropped_shape:?} do not agree"
        )));
    }
    let metadata = header.metadata().clone().unwrap_or_default();
    let field = |key: &str| metadata.get(key).cloned().unwrap_or_default();
    let origin = StartsOrigin {
        scene: field("scene"),
        command: field("command"),
    };
    let starts = (0..n)
        .map(|k| RecordedStart {
            state: states[k * size..(k + 1) * size].to_vec(),
            pose_goal: goals[k * POSE_GOAL..(k + 1) * POSE_GOAL].to_vec(),
            dropped: dropped[k] != 0.0,
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
                pose_goal: vec![0.1 * k as f64; POSE_GOAL],
                dropped: k == 1,
            })
            .collect();
        let origin = StartsOrigin {
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
}
