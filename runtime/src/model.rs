//! A trained model: the `.onnx` file opened once in onnxruntime, with its metadata read and
//! checked against the contract of [`crate::model_file`].

use std::path::{Path, PathBuf};

use ndarray::{Array3, ArrayView3};
use ort::session::Session;
use ort::session::builder::GraphOptimizationLevel;
use ort::value::Tensor;
use thiserror::Error;

use crate::model_file::{MetadataError, ModelMetadata, parse_metadata};
use crate::network::{INPUT_FEATURES, INPUT_STEP, OUTPUT_FEATURES};
use crate::onnxruntime::{self, RuntimeLibraryError};

/// Why a model could not be opened or run.
#[derive(Debug, Error)]
pub enum ModelError {
    /// The onnxruntime library is missing or would not load.
    #[error(transparent)]
    Runtime(#[from] RuntimeLibraryError),
    /// No file at the path.
    #[error("model file '{0}' does not exist")]
    Missing(PathBuf),
    /// The file exists but could not be read.
    #[error("could not read model file '{path}': {source}")]
    Read {
        /// The model file.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// onnxruntime would not load the bytes as a model (truncated, not ONNX, unsupported op).
    #[error("'{path}' is not a loadable ONNX model: {message}")]
    NotOnnx {
        /// The model file.
        path: PathBuf,
        /// What onnxruntime said.
        message: String,
    },
    /// The file's sinmdm metadata is missing, of another schema, malformed or breaks a rule.
    #[error(transparent)]
    Metadata(#[from] MetadataError),
    /// The graph's inputs or outputs are not the contract's.
    #[error("'{path}' does not have the denoiser's interface: {message}")]
    BadGraph {
        /// The model file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A denoiser call with features of the wrong shape.
    #[error("the model expects features of {expected} rows, got {got}")]
    FeatureRows {
        /// F of the model.
        expected: usize,
        /// Rows given.
        got: usize,
    },
    /// A denoiser call whose timesteps do not match its batch.
    #[error("a denoiser call needs one diffusion step per batch row: {rows} rows, {steps} steps")]
    StepCount {
        /// Batch rows of `x_t`.
        rows: usize,
        /// Timesteps given.
        steps: usize,
    },
    /// onnxruntime failed while running the graph.
    #[error("onnxruntime failed running '{path}': {message}")]
    Run {
        /// The model file.
        path: PathBuf,
        /// What onnxruntime said.
        message: String,
    },
}

/// How a model's onnxruntime session is set up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ModelOptions {
    /// Threads for one denoiser call; `None` uses every core.
    pub threads: Option<usize>,
}

/// A trained denoiser, ready to run.
pub struct Model {
    session: Session,
    metadata: ModelMetadata,
    path: PathBuf,
}

impl std::fmt::Debug for Model {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Model")
            .field("path", &self.path)
            .field("network", &self.metadata.network)
            .finish_non_exhaustive()
    }
}

/// Checks the graph's inputs and outputs against the contract of [`crate::network`]: `x_t`
/// f32 `[B, F, N]`, `t` i64 `[B]` in, `x0` f32 `[B, F, N]` out, with F the metadata's.
fn check_interface(session: &Session, features: usize) -> Result<(), String> {
    use ort::value::TensorElementType::{Float32, Int64};
    let names = |outlets: &[ort::value::Outlet]| {
        outlets
            .iter()
            .map(|o| o.name().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let (inputs, outputs) = (session.inputs(), session.outputs());
    let find = |outlets: &[ort::value::Outlet], name: &str| {
        outlets
            .iter()
            .find(|o| o.name() == name)
            .map(|o| o.dtype().clone())
    };
    let (Some(x), Some(t), Some(x0), 2) = (
        find(inputs, INPUT_FEATURES),
        find(inputs, INPUT_STEP),
        find(outputs, OUTPUT_FEATURES),
        inputs.len(),
    ) else {
        return Err(format!(
            "inputs [{}] and outputs [{}], expected inputs [{INPUT_FEATURES}, {INPUT_STEP}] and output {OUTPUT_FEATURES}",
            names(inputs),
            names(outputs)
        ));
    };
    let f = features as i64;
    let expect = |name: &str, dtype: &ort::value::ValueType, ty, rank: usize, rows: Option<i64>| {
        let shape = dtype.tensor_shape().map(|s| s.to_vec());
        let fits = dtype.tensor_type() == Some(ty)
            && shape
                .as_ref()
                .is_some_and(|s| s.len() == rank && rows.is_none_or(|r| s[1] == r || s[1] < 0));
        if fits {
            Ok(())
        } else {
            Err(format!(
                "'{name}' is {dtype:?}; the contract is {ty:?} of rank {rank}{}",
                rows.map_or(String::new(), |r| format!(" with {r} feature rows"))
            ))
        }
    };
    expect(INPUT_FEATURES, &x, Float32, 3, Some(f))?;
    expect(INPUT_STEP, &t, Int64, 1, None)?;
    expect(OUTPUT_FEATURES, &x0, Float32, 3, Some(f))
}

/// A session over `bytes` with `threads` intra-op threads and no spinning when idle.
fn open_session(
    environment: &ort::environment::Environment,
    bytes: &[u8],
    threads: usize,
) -> ort::Result<Session> {
    Session::builder(environment)?
        .with_optimization_level(GraphOptimizationLevel::Level3)?
        .with_intra_threads(threads)?
        .with_inter_threads(1)?
        .with_intra_op_spinning(false)?
        .with_inter_op_spinning(false)?
        .commit_from_memory(bytes)
}

impl Model {
    /// Opens a model file: loads onnxruntime if needed, reads the file, checks the metadata and
    /// the graph's interface.
    pub fn open(path: impl AsRef<Path>, options: &ModelOptions) -> Result<Model, ModelError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| {
            if source.kind() == std::io::ErrorKind::NotFound {
                ModelError::Missing(path.to_path_buf())
            } else {
                ModelError::Read {
                    path: path.to_path_buf(),
                    source,
                }
            }
        })?;
        Model::from_bytes(&bytes, path, options)
    }

    /// Opens a model held in memory (`name` is used in messages).
    pub fn from_bytes(
        bytes: &[u8],
        name: impl AsRef<Path>,
        options: &ModelOptions,
    ) -> Result<Model, ModelError> {
        let path = name.as_ref().to_path_buf();
        let runtime = onnxruntime::init()?;
        let not_onnx = |message: String| ModelError::NotOnnx {
            path: path.clone(),
            message,
        };
        let threads = options.threads.unwrap_or_else(|| {
            std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
        });
        let session = open_session(&runtime.environment, bytes, threads.max(1))
            .map_err(|e| not_onnx(e.to_string()))?;
        let metadata = {
            let meta = session.metadata().map_err(|e| not_onnx(e.to_string()))?;
            parse_metadata(&path, |key| meta.custom(key))?
        };
        check_interface(&session, metadata.network.features).map_err(|message| {
            ModelError::BadGraph {
                path: path.clone(),
                message,
            }
        })?;
        Ok(Model {
            session,
            metadata,
            path,
        })
    }

    /// Everything the file says besides the graph.
    pub fn metadata(&self) -> &ModelMetadata {
        &self.metadata
    }

    /// The file the model came from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The skeleton the model makes motion for (joint names, parents, offsets, channels).
    pub fn skeleton(&self) -> &crate::motion::Skeleton {
        &self.metadata.layout.skeleton
    }

    /// Frames per second of the motion the model makes.
    pub fn fps(&self) -> f64 {
        self.metadata.layout.fps
    }

    /// Frames of the clip the model was trained on (generation defaults to twice this).
    pub fn clip_frames(&self) -> usize {
        self.metadata.training.clip_frames
    }

    /// Feature rows F.
    pub fn features(&self) -> usize {
        self.metadata.network.features
    }

    /// One denoiser call: noisy normalised features `x_t` `[B, F, N]` at diffusion steps `t`
    /// (one per batch row) to the predicted clean features `[B, F, N]`.
    pub fn denoise(
        &mut self,
        x_t: ArrayView3<'_, f32>,
        t: &[i64],
    ) -> Result<Array3<f32>, ModelError> {
        let (b, f, n) = x_t.dim();
        if f != self.features() {
            return Err(ModelError::FeatureRows {
                expected: self.features(),
                got: f,
            });
        }
        if t.len() != b {
            return Err(ModelError::StepCount {
                rows: b,
                steps: t.len(),
            });
        }
        let path = self.path.clone();
        let run_failed = |e: ort::Error| ModelError::Run {
            path: path.clone(),
            message: e.to_string(),
        };
        let data: Vec<f32> = match x_t.as_slice() {
            Some(s) => s.to_vec(),
            None => x_t.iter().copied().collect(),
        };
        let xs = Tensor::from_array(([b, f, n], data.into_boxed_slice())).map_err(run_failed)?;
        let ts = Tensor::from_array(([b], t.to_vec().into_boxed_slice())).map_err(run_failed)?;
        let outputs = self
            .session
            .run(ort::inputs![INPUT_FEATURES => xs, INPUT_STEP => ts])
            .map_err(run_failed)?;
        let (shape, values) = outputs[OUTPUT_FEATURES]
            .try_extract_tensor::<f32>()
            .map_err(run_failed)?;
        if shape.to_vec() != [b as i64, f as i64, n as i64] {
            return Err(ModelError::Run {
                path,
                message: format!("output shape {shape:?}, expected [{b}, {f}, {n}]"),
            });
        }
        Array3::from_shape_vec((b, f, n), values.to_vec()).map_err(|e| ModelError::Run {
            path: self.path.clone(),
            message: format!("output of {} values: {e}", values.len()),
        })
    }
}

impl crate::diffusion::Denoiser for Model {
    type Error = ModelError;

    fn features(&self) -> usize {
        Model::features(self)
    }

    fn denoise(&mut self, x_t: ArrayView3<'_, f32>, t: &[i64]) -> Result<Array3<f32>, ModelError> {
        Model::denoise(self, x_t, t)
    }
}
