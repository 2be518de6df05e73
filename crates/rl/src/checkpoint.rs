//! Checkpoints and shipped policies on disk: network weights as safetensors, everything else
//! (configuration, normalisers, progress) as JSON. Every file is written to a temporary name
//! and renamed, so a killed run never leaves a half-written or corrupt checkpoint; loading
//! checks names and shapes and says what does not fit.

use std::fmt;
use std::path::{Path, PathBuf};

use safetensors::tensor::{Dtype, TensorView};

use crate::params::NamedTensor;

/// The file with `extension` of the files sharing `prefix`: appended, so that a prefix with a
/// dot in its name (`runs/rot-lead0.5`) keeps it, where `Path::with_extension` would replace
/// the text after the dot; a prefix given with one of its files' extensions (`own`) names the
/// same files.
pub fn file_beside(prefix: &Path, extension: &str, own: &[&str]) -> PathBuf {
    match prefix.extension().and_then(|e| e.to_str()) {
        Some(given) if own.contains(&given) => prefix.with_extension(extension),
        _ => {
            let mut name = prefix.as_os_str().to_owned();
            name.push(".");
            name.push(extension);
            PathBuf::from(name)
        }
    }
}

#[derive(Debug)]
pub enum CheckpointError {
    Io {
        path: PathBuf,
        message: String,
    },
    Corrupt {
        path: PathBuf,
        message: String,
    },
    Mismatch {
        path: PathBuf,
        message: String,
    },
    /// A policy that fits, asked to be made into one it cannot be (led on twice, say).
    Refused {
        path: PathBuf,
        message: String,
    },
}

impl fmt::Display for CheckpointError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CheckpointError::Io { path, message } => {
                write!(f, "cannot read or write {}: {message}", path.display())
            }
            CheckpointError::Corrupt { path, message } => write!(
                f,
                "{} is not a valid checkpoint file ({message}); it may be truncated: restore it or train again",
                path.display()
            ),
            CheckpointError::Mismatch { path, message } => write!(
                f,
                "{} does not fit this network ({message}); it was saved with another configuration or environment",
                path.display()
            ),
            CheckpointError::Refused { path, message } => {
                write!(f, "{} cannot be used so: {message}", path.display())
            }
        }
    }
}

impl std::error::Error for CheckpointError {}

/// Writes `bytes` to `path` through a temporary file and a rename.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), CheckpointError> {
    let io = |e: std::io::Error| CheckpointError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(io)?;
    }
    let mut temporary = path.to_path_buf();
    temporary.as_mut_os_string().push(".tmp");
    std::fs::write(&temporary, bytes).map_err(io)?;
    std::fs::rename(&temporary, path).map_err(io)
}

/// Saves tensors as a safetensors file.
pub fn save_tensors(path: &Path, tensors: &[NamedTensor]) -> Result<(), CheckpointError> {
    let raw: Vec<RawTensor> = tensors
        .iter()
        .map(|t| RawTensor {
            name: t.name.clone(),
            dtype: Dtype::F32,
            shape: t.shape.clone(),
            data: t.values.iter().flat_map(|v| v.to_le_bytes()).collect(),
        })
        .collect();
    write_safetensors(path, &raw, None)
}

/// A tensor's little-endian bytes, as a safetensors file holds them.
pub struct RawTensor {
    pub name: String,
    pub dtype: Dtype,
    pub shape: Vec<usize>,
    pub data: Vec<u8>,
}

/// Writes tensors, with optional text metadata, as a safetensors file (atomically).
pub fn write_safetensors(
    path: &Path,
    tensors: &[RawTensor],
    metadata: Option<std::collections::HashMap<String, String>>,
) -> Result<(), CheckpointError> {
    let io = |message: String| CheckpointError::Io {
        path: path.to_path_buf(),
        message,
    };
    let views = tensors
        .iter()
        .map(|t| TensorView::new(t.dtype, t.shape.clone(), &t.data).map(|v| (t.name.clone(), v)))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| io(e.to_string()))?;
    let serialized = safetensors::serialize(views, metadata).map_err(|e| io(e.to_string()))?;
    write_atomically(path, &serialized)
}

/// Loads every tensor of a safetensors file (float32 only).
pub fn load_tensors(path: &Path) -> Result<Vec<NamedTensor>, CheckpointError> {
    let bytes = std::fs::read(path).map_err(|e| CheckpointError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let corrupt = |message: String| CheckpointError::Corrupt {
        path: path.to_path_buf(),
        message,
    };
    let file = safetensors::SafeTensors::deserialize(&bytes).map_err(|e| corrupt(e.to_string()))?;
    let mut out = Vec::new();
    for (name, view) in file.tensors() {
        if view.dtype() != Dtype::F32 {
            return Err(corrupt(format!(
                "tensor '{name}' is {:?}, not F32",
                view.dtype()
            )));
        }
        let values = view
            .data()
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        out.push(NamedTensor {
            name,
            shape: view.shape().to_vec(),
            values,
        });
    }
    Ok(out)
}

/// Saves a value as pretty JSON.
pub fn save_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<(), CheckpointError> {
    let text = serde_json::to_string_pretty(value).map_err(|e| CheckpointError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    write_atomically(path, text.as_bytes())
}

/// Loads a JSON value.
pub fn load_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, CheckpointError> {
    let text = std::fs::read_to_string(path).map_err(|e| CheckpointError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    serde_json::from_str(&text).map_err(|e| CheckpointError::Corrupt {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}
