//! A trained model: the `.onnx` file opened once in onnxruntime, with its metadata read and
//! checked against the contract of [`crate::model_file`].

use std::path::{Path, PathBuf};

use ndarray::{Array3, ArrayView3};
use ort::session::Session;
use ort::session::builder::GraphOptimizationLevel;
use ort::value::Tensor;
use thiserror::Error;

use crate::model_file::{METADATA_KEY, ModelMetadata, SCHEMA_KEY, SCHEMA_VERSION};
use crate::onnxruntime::{self, RuntimeLibraryError};

/// Name of the graph input holding the noisy features.
pub const INPUT_FEATURES: &str = "x_t";
/// Name of the graph input holding the diffusion step of each batch row.
pub const INPUT_STEP: &str = "t";
/// Name of the graph output holding the predicted clean features.
pub const OUTPUT_FEATURES: &str = "x0";

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
    /// A valid ONNX file without our metadata.
    #[error(
        "'{path}' has no sinmdm metadata (no '{SCHEMA_KEY}' entry in metadata_props): it was not written by sinmdm-export"
    )]
    NoMetadata {
        /// The model file.
        path: PathBuf,
    },
    /// Our metadata, but a schema version this runtime does not read.
    #[error(
        "'{path}' carries sinmdm metadata schema '{found}'; this runtime reads schema {SCHEMA_VERSION}"
    )]
    SchemaVersion {
        /// The model file.
        path: PathBuf,
        /// The version in the file.
        found: String,
    },
    /// The metadata is present but incomplete or malformed.
    #[error("'{path}' has invalid sinmdm metadata: {message}")]
    BadMetadata {
        /// The model file.
        path: PathBuf,
        /// What is wrong, naming the field.
        message: String,
    },
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

/// Reads and checks the metadata entries of a model, given a lookup of `metadata_props`.
pub fn parse_metadata(
    path: &Path,
    lookup: impl Fn(&str) -> Option<String>,
) -> Result<ModelMetadata, ModelError> {
    let schema = lookup(SCHEMA_KEY).ok_or_else(|| ModelError::NoMetadata {
        path: path.to_path_buf(),
    })?;
    if schema.trim() != SCHEMA_VERSION.to_string() {
        return Err(ModelError::SchemaVersion {
            path: path.to_path_buf(),
            found: schema,
        });
    }
    let bad = |message: String| ModelError::BadMetadata {
        path: path.to_path_buf(),
        message,
    };
    let json = lookup(METADATA_KEY).ok_or_else(|| bad(format!("no '{METADATA_KEY}' entry")))?;
    let metadata: ModelMetadata =
        serde_json::from_str(&json).map_err(|e| bad(format!("'{METADATA_KEY}': {e}")))?;
    check_consistent(&metadata).map_err(bad)?;
    Ok(metadata)
}

/// Cross-checks of the metadata's parts against each other.
fn check_consistent(m: &ModelMetadata) -> Result<(), String> {
    let width = m.layout.width();
    if m.network.features != width {
        return Err(format!(
            "network.features is {} but the feature layout has {width} columns",
            m.network.features
        ));
    }
    if m.normalizer.mean.len() != width || m.normalizer.std.len() != width {
        return Err(format!(
            "the normalizer has {} means and {} stds for {width} features",
            m.normalizer.mean.len(),
            m.normalizer.std.len()
        ));
    }
    if let Some(i) = m
        .normalizer
        .std
        .iter()
        .position(|s| !(s.is_finite() && *s > 0.0))
    {
        return Err(format!("normalizer.std[{i}] is not a positive number"));
    }
    if m.diffusion.schedule != "cosine" || m.diffusion.prediction != "x0" {
        return Err(format!(
            "diffusion.schedule '{}' / prediction '{}': this runtime runs 'cosine' / 'x0'",
            m.diffusion.schedule, m.diffusion.prediction
        ));
    }
    if m.diffusion.steps < 2 {
        return Err(format!("diffusion.steps is {}", m.diffusion.steps));
    }
    if !(m.layout.fps.is_finite() && m.layout.fps > 0.0) {
        return Err(format!("layout.fps is {}", m.layout.fps));
    }
    Ok(())
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
        let inputs: Vec<&str> = session.inputs().iter().map(|o| o.name()).collect();
        let outputs: Vec<&str> = session.outputs().iter().map(|o| o.name()).collect();
        if inputs.len() != 2
            || !inputs.contains(&INPUT_FEATURES)
            || !inputs.contains(&INPUT_STEP)
            || !outputs.contains(&OUTPUT_FEATURES)
        {
            return Err(ModelError::BadGraph {
                path,
                message: format!(
                    "inputs [{}] and outputs [{}], expected inputs [{INPUT_FEATURES}, {INPUT_STEP}] and output {OUTPUT_FEATURES}",
                    inputs.join(", "),
                    outputs.join(", ")
                ),
            });
        }
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
        assert_eq!(t.len(), b, "one diffusion step per batch row");
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
        Ok(Array3::from_shape_vec((b, f, n), values.to_vec()).expect("shape checked above"))
    }
}

impl crate::diffusion::sampler::Denoiser for Model {
    type Error = ModelError;

    fn features(&self) -> usize {
        Model::features(self)
    }

    fn denoise(&mut self, x_t: ArrayView3<'_, f32>, t: &[i64]) -> Result<Array3<f32>, ModelError> {
        Model::denoise(self, x_t, t)
    }
}
