//! One onnxruntime call for many samples, as an opt-in: [`OneCallPerThread`] denoises a batch
//! as one call per thread (its rows split in contiguous shares) where [`Model`] makes one call
//! per sample.
//!
//! Per sample, onnxruntime's CPU kernels have given every row of a batched call the same bits
//! as that sample alone (onnxruntime 1.31.1 on AVX2, batches of 1 to 64: the lab's "One network
//! call for many samples"), and the crowd tests check it on the test model; but onnxruntime
//! does not promise it, so the per-sample call stays the default and this is the opt-in that
//! buys what one call saves (1.1-1.45x in the lab).

use ndarray::{Array3, ArrayView3};

use crate::diffusion::Denoiser;
use crate::model::{Calls, Model, ModelError};

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
        self.0.denoise_in_calls(x_t, t, out, Calls::PerThread)
    }
}
