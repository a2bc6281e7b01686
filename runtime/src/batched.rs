//! One onnxruntime call for many samples, as an opt-in: [`OneCallPerThread`] denoises a batch
//! as one call per thread (its rows split in contiguous shares) where [`Model`] makes one call
//! per sample.
//!
//! Per sample, onnxruntime's CPU kernels have given every row of a batched call the same bits
//! as that sample alone (onnxruntime 1.31.1 on AVX2, batches of 1 to 64: the lab's "One network
//! call for many samples"), and the crowd tests check it on the test model; but onnxruntime
//! does not promise it, so the per-sample call stays the default and this is the opt-in that
//! buys what one call saves (1.1-1.45x in the lab).

use ndarray::{Array3, ArrayView3, ArrayViewMut3, Axis, s};
use ort::session::Session;
use ort::value::TensorRef;

use crate::diffusion::Denoiser;
use crate::model::{Model, ModelError};
use crate::network::{INPUT_FEATURES, INPUT_STEP, OUTPUT_FEATURES};

/// A [`Model`] that denoises a batch in one onnxruntime call per thread; see the
/// [module documentation](self).
#[derive(Debug)]
pub struct OneCallPerThread<'a>(pub &'a mut Model);

impl Denoiser for OneCallPerThread<'_> {
    type Error = ModelError;

    fn features(&self) -> usize {
        self.0.features()
    }

    fn denoise(&mut self, x_t: ArrayView3<'_, f32>, t: &[i64]) -> Result<Array3<f32>, ModelError> {
        let mut out = Array3::zeros(x_t.dim());
        self.denoise_into(x_t, t, &mut out)?;
        Ok(out)
    }

    fn denoise_into(
        &mut self,
        x_t: ArrayView3<'_, f32>,
        t: &[i64],
        out: &mut Array3<f32>,
    ) -> Result<(), ModelError> {
        let (b, f, n) = x_t.dim();
        if f != self.0.features() {
            return Err(ModelError::FeatureRows {
                expected: self.0.features(),
                got: f,
            });
        }
        if t.len() != b {
            return Err(ModelError::StepCount {
                rows: b,
                steps: t.len(),
            });
        }
        if out.dim() != (b, f, n) || !out.is_standard_layout() {
            *out = Array3::zeros((b, f, n));
        }
        if b == 0 {
            return Ok(());
        }
        let workers = self.0.threads().min(b).max(1);
        let (sessions, path) = self.0.sessions(workers)?;
        let share = b.div_ceil(workers);
        std::thread::scope(|scope| {
            let mut handles = Vec::new();
            let mut own = None;
            let outs = out.axis_chunks_iter_mut(Axis(0), share);
            for (k, (session, target)) in sessions.iter_mut().zip(outs).enumerate() {
                let rows = k * share..(k * share + share).min(b);
                let x = x_t.slice(s![rows.clone(), .., ..]);
                let steps = &t[rows];
                if k == 0 {
                    own = Some((session, x, steps, target));
                    continue;
                }
                // A share whose thread the system refuses runs here instead: the values are
                // the same wherever a share runs.
                let work = move || denoise_rows(session, path, x, steps, target);
                match std::thread::Builder::new()
                    .name("sinmdm-denoise".into())
                    .spawn_scoped(scope, work)
                {
                    Ok(handle) => handles.push(handle),
                    Err(e) => {
                        return Err(ModelError::Run {
                            path: path.to_path_buf(),
                            message: format!("the system refused a thread for the batch: {e}"),
                        });
                    }
                }
            }
            let mut result = match own {
                Some((session, x, steps, target)) => denoise_rows(session, path, x, steps, target),
                None => Ok(()),
            };
            for handle in handles {
                let joined = handle.join().unwrap_or_else(|_| {
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

/// Rows `x` `[B, F, N]` at steps `t` through `session` in one call, written into `target`.
fn denoise_rows(
    session: &mut Session,
    path: &std::path::Path,
    x: ArrayView3<'_, f32>,
    t: &[i64],
    mut target: ArrayViewMut3<'_, f32>,
) -> Result<(), ModelError> {
    let (b, f, n) = x.dim();
    let run_failed = |e: ort::Error| ModelError::Run {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let copied: Vec<f32>;
    let data = match x.as_slice() {
        Some(s) => s,
        None => {
            copied = x.iter().copied().collect();
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
