//! A module's parameters by name, read out and written back, for polyak averaging and for
//! safetensors checkpoints. Names are burn's module paths, e.g. `layers.0.weight`.

use burn::module::{Module, ModuleMapper, ModuleVisitor, Param};
use burn::prelude::*;
use burn::tensor::TensorData;

/// One parameter tensor.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedTensor {
    pub name: String,
    pub shape: Vec<usize>,
    pub values: Vec<f32>,
}

/// How far apart two sets of the same parameters are: the sum of absolute differences,
/// parameters paired by name whatever order each set is in (a safetensors file is read back in
/// its own order). For tests and diagnostics: whether training moved a network.
pub fn l1_distance(a: &[NamedTensor], b: &[NamedTensor]) -> f32 {
    fn by_name(set: &[NamedTensor]) -> Vec<&NamedTensor> {
        let mut sorted: Vec<&NamedTensor> = set.iter().collect();
        sorted.sort_by(|x, y| x.name.cmp(&y.name));
        sorted
    }
    by_name(a)
        .into_iter()
        .zip(by_name(b))
        .map(|(x, y)| {
            assert_eq!(x.name, y.name, "the same parameters on both sides");
            x.values
                .iter()
                .zip(&y.values)
                .map(|(p, q)| (p - q).abs())
                .sum::<f32>()
        })
        .sum()
}

/// `tensors` with `prefix` put before their names, as one file stores several networks (an
/// ensemble's partners, a guide's critics).
pub fn prefixed(tensors: Vec<NamedTensor>, prefix: &str) -> Vec<NamedTensor> {
    tensors
        .into_iter()
        .map(|t| NamedTensor {
            name: format!("{prefix}{}", t.name),
            ..t
        })
        .collect()
}

/// The tensors of `tensors` stored under `prefix`, with it taken off their names.
pub fn under_prefix(tensors: &[NamedTensor], prefix: &str) -> Vec<NamedTensor> {
    tensors
        .iter()
        .filter_map(|t| {
            Some(NamedTensor {
                name: t.name.strip_prefix(prefix)?.to_string(),
                ..t.clone()
            })
        })
        .collect()
}

/// Every float parameter of `module`, in visiting order.
pub fn read<M: Module>(module: &M) -> Vec<NamedTensor> {
    struct Reader {
        path: Vec<String>,
        out: Vec<NamedTensor>,
    }
    impl ModuleVisitor for Reader {
        fn enter_module(&mut self, name: &str, _: &str) {
            self.path.push(name.to_string());
        }
        fn exit_module(&mut self, _: &str, _: &str) {
            self.path.pop();
        }
        fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
            let tensor = param.val();
            let shape = tensor.dims().to_vec();
            let values = tensor
                .into_data()
                .convert::<f32>()
                .try_to_vec::<f32>()
                .unwrap_or_default();
            self.out.push(NamedTensor {
                name: self.path.join("."),
                shape,
                values,
            });
        }
    }
    let mut reader = Reader {
        path: vec![],
        out: vec![],
    };
    module.visit(&mut reader);
    reader.out
}

/// Gives the layer whose weight is `weight` (`[inputs, outputs]`, as burn's `Linear` keeps
/// it) `extra` more inputs at row `at`, with zero weights: the network computes what it did
/// before, whatever the new inputs hold, and learns to use them. False if there is no such
/// tensor or `at` is past its inputs.
pub fn insert_zero_inputs(
    tensors: &mut [NamedTensor],
    weight: &str,
    at: usize,
    extra: usize,
) -> bool {
    let Some(tensor) = tensors.iter_mut().find(|t| t.name == weight) else {
        return false;
    };
    let [inputs, outputs] = tensor.shape[..] else {
        return false;
    };
    if at > inputs {
        return false;
    }
    let zeros = std::iter::repeat_n(0.0, extra * outputs);
    tensor.values.splice(at * outputs..at * outputs, zeros);
    tensor.shape = vec![inputs + extra, outputs];
    true
}

/// Sets the parameters `saved` from a network into `fresh`, the freshly made parameters of the
/// same network with wider hidden layers, so that the wider network computes what the saved
/// one did. Each saved tensor fills the first rows and columns of its fresh one (a weight is
/// `[inputs, outputs]`); the weights from a new unit to an old one are zero; the new units
/// keep their fresh weights and biases. A new unit so starts with random inputs and no say in
/// the output, and gradients reach it at once through its zero outgoing weights. (Net2Net's
/// aim, Chen, Goodfellow and Shlens 2016, without its copied units, which would learn alike.)
/// Tensors of the same shape are taken as saved. Fails, saying why, if a tensor is missing or
/// a saved one is larger than its fresh one in any dimension, as of a deeper, narrower or
/// other network.
pub fn embed_in_wider(
    saved: &[NamedTensor],
    fresh: Vec<NamedTensor>,
) -> Result<Vec<NamedTensor>, String> {
    if saved.len() != fresh.len() {
        return Err(format!(
            "{} saved tensors, {} in this network: only the hidden layers' width can grow",
            saved.len(),
            fresh.len()
        ));
    }
    fresh
        .into_iter()
        .map(|mut wide| {
            let narrow = saved
                .iter()
                .find(|t| t.name == wide.name)
                .ok_or_else(|| format!("no saved tensor named '{}'", wide.name))?;
            match (&narrow.shape[..], &wide.shape[..]) {
                (a, b) if a == b => return Ok(narrow.clone()),
                (&[rows], &[wide_rows]) if rows <= wide_rows => {
                    wide.values[..rows].copy_from_slice(&narrow.values);
                }
                (&[rows, cols], &[wide_rows, wide_cols])
                    if rows <= wide_rows && cols <= wide_cols =>
                {
                    for r in 0..wide_rows {
                        let row = &mut wide.values[r * wide_cols..r * wide_cols + cols];
                        if r < rows {
                            row.copy_from_slice(&narrow.values[r * cols..(r + 1) * cols]);
                        } else {
                            row.fill(0.0);
                        }
                    }
                }
                (a, b) => {
                    return Err(format!(
                        "'{}' is saved as {a:?} and cannot grow into {b:?}",
                        wide.name
                    ));
                }
            }
            Ok(wide)
        })
        .collect()
}

/// A parameter that did not fit.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamMismatch {
    Missing(String),
    Shape {
        name: String,
        expected: Vec<usize>,
        found: Vec<usize>,
    },
}

impl std::fmt::Display for ParamMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ParamMismatch::Missing(name) => write!(f, "no tensor named '{name}'"),
            ParamMismatch::Shape {
                name,
                expected,
                found,
            } => {
                write!(
                    f,
                    "'{name}' has shape {found:?}, the network needs {expected:?}"
                )
            }
        }
    }
}

impl std::error::Error for ParamMismatch {}

/// `module` with each parameter replaced by `blend(current, given)`, where `given` is the
/// tensor of the same name in `values`. The results are detached from any autodiff graph.
pub fn write<M: Module>(
    module: M,
    values: &[NamedTensor],
    blend: impl Fn(&[f32], &[f32]) -> Vec<f32>,
) -> Result<M, ParamMismatch> {
    struct Writer<'a, B> {
        path: Vec<String>,
        values: &'a [NamedTensor],
        blend: B,
        error: Option<ParamMismatch>,
    }
    impl<B: Fn(&[f32], &[f32]) -> Vec<f32>> ModuleMapper for Writer<'_, B> {
        fn enter_module(&mut self, name: &str, _: &str) {
            self.path.push(name.to_string());
        }
        fn exit_module(&mut self, _: &str, _: &str) {
            self.path.pop();
        }
        fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
            let name = self.path.join(".");
            let Some(given) = self.values.iter().find(|v| v.name == name) else {
                self.error.get_or_insert(ParamMismatch::Missing(name));
                return param;
            };
            param.map(|tensor| {
                let expected = tensor.dims().to_vec();
                if given.shape != expected {
                    self.error.get_or_insert(ParamMismatch::Shape {
                        name: name.clone(),
                        expected,
                        found: given.shape.clone(),
                    });
                    return tensor;
                }
                let device = tensor.device();
                let current = tensor
                    .into_data()
                    .convert::<f32>()
                    .try_to_vec::<f32>()
                    .unwrap_or_default();
                let blended = (self.blend)(&current, &given.values);
                Tensor::from_data(TensorData::new(blended, given.shape.clone()), &device).detach()
            })
        }
    }
    let mut writer = Writer {
        path: vec![],
        values,
        blend,
        error: None,
    };
    let module = module.map(&mut writer);
    match writer.error {
        Some(error) => Err(error),
        None => Ok(module),
    }
}
