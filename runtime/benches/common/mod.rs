//! What the runtime's benchmarks share: the model they run by default, a session opened as the
//! runtime opens its own, the model with its time inside onnxruntime counted, and the median.
//! Each bench uses some of it.
#![allow(dead_code)]

/// The shipped walk model, every bench's default.
pub const SHIPPED_WALK: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../onnx-models/human_walk_cmu.onnx"
);

/// The first command-line argument that names an `.onnx` file (cargo bench passes flags of its
/// own beside it), else [`SHIPPED_WALK`].
pub fn model_argument() -> String {
    std::env::args()
        .skip(1)
        .find(|a| a.ends_with(".onnx"))
        .unwrap_or_else(|| SHIPPED_WALK.into())
}

use std::time::Instant;

use ndarray::{Array3, ArrayView3};
use ort::session::Session;
use ort::session::builder::GraphOptimizationLevel;
use sinmdm::{Denoiser, Model, ModelError};

/// A plain onnxruntime session on `path` with the runtime's options (full graph optimisation,
/// one inter-op thread, no spinning) on an intra-op pool of `threads` threads.
pub fn open_session(path: &str, threads: usize) -> Session {
    let rt = sinmdm::init_onnxruntime().expect("onnxruntime");
    Session::builder(rt.environment())
        .and_then(|s| Ok(s.with_optimization_level(GraphOptimizationLevel::All)?))
        .and_then(|s| Ok(s.with_intra_threads(threads)?))
        .and_then(|s| Ok(s.with_inter_threads(1)?))
        .and_then(|s| Ok(s.with_intra_op_spinning(false)?))
        .and_then(|mut s| s.commit_from_file(path))
        .expect("session")
}

/// The model, with the seconds spent in its calls counted in `inside`.
pub struct Timed<'a> {
    pub model: &'a mut Model,
    pub inside: f64,
}

impl Denoiser for Timed<'_> {
    type Error = ModelError;
    fn features(&self) -> usize {
        self.model.features()
    }
    fn denoise(&mut self, x_t: ArrayView3<'_, f32>, t: &[i64]) -> Result<Array3<f32>, ModelError> {
        let start = Instant::now();
        let out = self.model.denoise(x_t, t);
        self.inside += start.elapsed().as_secs_f64();
        out
    }
    fn denoise_into(
        &mut self,
        x_t: ArrayView3<'_, f32>,
        t: &[i64],
        out: &mut Array3<f32>,
    ) -> Result<(), ModelError> {
        let start = Instant::now();
        let done = self.model.denoise_into(x_t, t, out);
        self.inside += start.elapsed().as_secs_f64();
        done
    }
}

/// The median of `values` (the upper one of an even count).
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
