//! A trained model: the `.onnx` file opened once in onnxruntime, with its metadata read and
//! checked against the contract of [`crate::model_file`].

use std::path::{Path, PathBuf};

use ndarray::{Array3, ArrayView3, Axis};
use ort::session::Session;
use ort::session::builder::GraphOptimizationLevel;
use ort::value::TensorRef;
use thiserror::Error;

use crate::limits::MAX_THREADS;
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
    /// The file exists but could not be read (or is not a regular file, or is larger than
    /// [`MAX_MODEL_BYTES`]). The reason is said in the message, not chained, so it is said once.
    #[error("could not read model file '{path}': {reason}")]
    Read {
        /// The model file.
        path: PathBuf,
        /// What the system said, or the limit the file broke.
        reason: std::io::Error,
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
    /// More threads than [`crate::limits::MAX_THREADS`].
    #[error("a model runs on 1 to {MAX_THREADS} threads (0 or none: every core), got {0}")]
    Threads(usize),
    /// onnxruntime failed while running the graph.
    #[error("onnxruntime failed running '{path}': {message}")]
    Run {
        /// The model file.
        path: PathBuf,
        /// What onnxruntime said.
        message: String,
    },
}

/// How a model's onnxruntime sessions are set up.
///
/// The same bits on every machine: each sample of a batch is its own onnxruntime call on one
/// intra-op thread, so a sample's values depend neither on the thread count nor on its place
/// in the batch. `threads` is how many samples run at once (one session and one thread each).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ModelOptions {
    /// Samples of a batch denoised at once, each on its own thread and session; `None` uses
    /// every core. At most [`crate::limits::MAX_THREADS`].
    pub threads: Option<usize>,
}

/// A trained denoiser, ready to run.
pub struct Model {
    /// One session per thread that has run a sample so far (made when a batch first needs it).
    sessions: Vec<Session>,
    /// The file's bytes, for the sessions not made yet.
    bytes: Vec<u8>,
    threads: usize,
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

/// A session over `bytes` that runs each call on the calling thread alone (one intra-op
/// thread: onnxruntime starts no thread pool, and a reduction's order never depends on how
/// work was split), with no spinning when idle.
fn open_session(environment: &ort::environment::Environment, bytes: &[u8]) -> ort::Result<Session> {
    Session::builder(environment)?
        .with_optimization_level(GraphOptimizationLevel::All)?
        .with_intra_threads(1)?
        .with_inter_threads(1)?
        .with_intra_op_spinning(false)?
        .with_inter_op_spinning(false)?
        .commit_from_memory(bytes)
}

use crate::limits::MAX_MODEL_BYTES;

/// The size limit of model files, for [`crate::files::read_regular_file`].
const MODEL_LIMIT: crate::files::FileLimit = crate::files::FileLimit {
    bytes: MAX_MODEL_BYTES,
    name: "MAX_MODEL_BYTES",
    what: "a model file",
};

impl Model {
    /// Opens a model file: loads onnxruntime if needed, reads the file (a regular file of at
    /// most [`MAX_MODEL_BYTES`]), checks the metadata and the graph's interface.
    pub fn open(path: impl AsRef<Path>, options: &ModelOptions) -> Result<Model, ModelError> {
        let path = path.as_ref();
        let bytes = crate::files::read_regular_file(path, MODEL_LIMIT, None).map_err(|source| {
            if source.kind() == std::io::ErrorKind::NotFound {
                ModelError::Missing(path.to_path_buf())
            } else {
                ModelError::Read {
                    path: path.to_path_buf(),
                    reason: source,
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
        let threads = match options.threads {
            Some(n) if n > MAX_THREADS => return Err(ModelError::Threads(n)),
            Some(n) => n.max(1),
            None => std::thread::available_parallelism()
                .map_or(1, std::num::NonZeroUsize::get)
                .min(MAX_THREADS),
        };
        let session =
            open_session(&runtime.environment, bytes).map_err(|e| not_onnx(e.to_string()))?;
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
            sessions: vec![session],
            bytes: bytes.to_vec(),
            threads,
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

    /// Samples of a batch this model denoises at once (threads), as opened.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Makes sure `count` sessions exist (one per thread a batch will use).
    fn sessions_for(&mut self, count: usize) -> Result<(), ModelError> {
        while self.sessions.len() < count {
            let runtime = onnxruntime::init()?;
            let session =
                open_session(&runtime.environment, &self.bytes).map_err(|e| ModelError::Run {
                    path: self.path.clone(),
                    message: format!("could not open another session: {e}"),
                })?;
            self.sessions.push(session);
        }
        Ok(())
    }

    /// One denoiser call: noisy normalised features `x_t` `[B, F, N]` at diffusion steps `t`
    /// (one per batch row) to the predicted clean features `[B, F, N]`.
    pub fn denoise(
        &mut self,
        x_t: ArrayView3<'_, f32>,
        t: &[i64],
    ) -> Result<Array3<f32>, ModelError> {
        let mut out = Array3::<f32>::zeros(x_t.dim());
        self.denoise_into(x_t, t, &mut out)?;
        Ok(out)
    }

    /// [`Model::denoise`] written into `out`, which is reshaped to `x_t`'s shape only if it
    /// has another (a sampler reuses one buffer from step to step).
    pub fn denoise_into(
        &mut self,
        x_t: ArrayView3<'_, f32>,
        t: &[i64],
        out: &mut Array3<f32>,
    ) -> Result<(), ModelError> {
        self.denoise_in_calls(x_t, t, out, Calls::PerSample)
    }

    /// [`Model::denoise_into`] with the batch's onnxruntime calls as `calls` says.
    pub(crate) fn denoise_in_calls(
        &mut self,
        x_t: ArrayView3<'_, f32>,
        t: &[i64],
        out: &mut Array3<f32>,
        calls: Calls,
    ) -> Result<(), ModelError> {
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
        let workers = self.threads.min(b).max(1);
        self.sessions_for(workers)?;
        if out.dim() != (b, f, n) || !out.is_standard_layout() {
            *out = Array3::zeros((b, f, n));
        }
        let path = self.path.as_path();
        // Per sample: sample i goes to thread i mod W, one call each. Per thread: thread k takes
        // the k-th contiguous share of rows in one call. Each thread has its own session, and the
        // first share runs on the calling thread.
        let rows_per_call = match calls {
            Calls::PerSample => 1,
            Calls::PerThread => b.div_ceil(workers).max(1),
        };
        let mut shares: Vec<Share<'_>> = (0..workers).map(|_| Vec::new()).collect();
        for (k, target) in out.axis_chunks_iter_mut(Axis(0), rows_per_call).enumerate() {
            shares[k % workers].push((k * rows_per_call, target));
        }
        let mut sessions = self.sessions[..workers].iter_mut();
        let mut shares = shares.into_iter();
        let (Some(own_session), Some(own_share)) = (sessions.next(), shares.next()) else {
            return Ok(());
        };
        std::thread::scope(|scope| {
            // A share whose thread the system refuses runs on the calling thread: the values
            // are the same wherever a sample runs.
            let mut result = Ok(());
            let mut others = Vec::new();
            for (session, share) in sessions.zip(shares) {
                let spawned = std::thread::Builder::new()
                    .name("sinmdm-denoise".into())
                    .spawn_scoped(scope, move || denoise_share(session, path, x_t, t, share));
                match spawned {
                    Ok(handle) => others.push(handle),
                    Err(_) => {
                        result = result.and(Err(ModelError::Run {
                            path: path.to_path_buf(),
                            message: "the system refused a thread for the batch".into(),
                        }))
                    }
                }
            }
            result = result.and(denoise_share(own_session, path, x_t, t, own_share));
            for other in others {
                let joined = other.join().unwrap_or_else(|_| {
                    Err(ModelError::Run {
                        path: path.to_path_buf(),
                        message: "a denoising thread panicked".into(),
                    })
                });
                result = result.and(joined);
            }
            result
        })
    }
}

/// How a batch goes through onnxruntime: one call per sample (the default, whose bits do not
/// depend on the batch), or one call per thread over a contiguous share of rows
/// ([`crate::OneCallPerThread`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Calls {
    PerSample,
    PerThread,
}

/// The calls one thread makes: each call's first row and the output rows it fills.
type Share<'a> = Vec<(usize, ndarray::ArrayViewMut3<'a, f32>)>;

/// Makes a thread's calls through one session.
fn denoise_share(
    session: &mut Session,
    path: &Path,
    x_t: ArrayView3<'_, f32>,
    t: &[i64],
    share: Share<'_>,
) -> Result<(), ModelError> {
    for (first, target) in share {
        let rows = first..first + target.dim().0;
        denoise_rows(
            session,
            path,
            x_t.slice(ndarray::s![rows.clone(), .., ..]),
            &t[rows],
            target,
        )?;
    }
    Ok(())
}

/// Rows `x_t` `[B, F, N]` at diffusion steps `t` (one per row) through `session` in one call,
/// written into `target`.
fn denoise_rows(
    session: &mut Session,
    path: &Path,
    x_t: ArrayView3<'_, f32>,
    t: &[i64],
    mut target: ndarray::ArrayViewMut3<'_, f32>,
) -> Result<(), ModelError> {
    let (b, f, n) = x_t.dim();
    let run_failed = |e: ort::Error| ModelError::Run {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    // Contiguous rows are lent to onnxruntime as they are (no copy); any others are copied.
    let copied: Vec<f32>;
    let data = match x_t.as_slice() {
        Some(s) => s,
        None => {
            copied = x_t.iter().copied().collect();
            &copied
        }
    };
    let xs = TensorRef::from_array_view(([b, f, n], data)).map_err(run_failed)?;
    let ts = TensorRef::from_array_view(([b], t)).map_err(run_failed)?;
    let outputs = session
        .run(ort::inputs![INPUT_FEATURES => xs, INPUT_STEP => ts])
        .map_err(run_failed)?;
    let (shape, values) = outputs[OUTPUT_FEATURES]
        .try_extract_tensor::<f32>()
        .map_err(run_failed)?;
    if shape.to_vec() != [b as i64, f as i64, n as i64] || values.len() != b * f * n {
        return Err(ModelError::Run {
            path: path.to_path_buf(),
            message: format!("output shape {shape:?}, expected [{b}, {f}, {n}]"),
        });
    }
    match target.as_slice_mut() {
        Some(slice) => slice.copy_from_slice(values),
        None => target.iter_mut().zip(values).for_each(|(o, v)| *o = *v),
    }
    Ok(())
}

impl crate::diffusion::Denoiser for Model {
    type Error = ModelError;

    fn features(&self) -> usize {
        Model::features(self)
    }

    fn denoise(&mut self, x_t: ArrayView3<'_, f32>, t: &[i64]) -> Result<Array3<f32>, ModelError> {
        Model::denoise(self, x_t, t)
    }

    fn denoise_into(
        &mut self,
        x_t: ArrayView3<'_, f32>,
        t: &[i64],
        out: &mut Array3<f32>,
    ) -> Result<(), ModelError> {
        Model::denoise_into(self, x_t, t, out)
    }
}
