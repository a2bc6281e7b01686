//! Plain named weights: the only thing the exporter needs from training.

use std::collections::BTreeMap;

use crate::ExportError;

/// One weight tensor, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct WeightTensor {
    /// Dimensions.
    pub shape: Vec<usize>,
    /// Values, row-major.
    pub values: Vec<f32>,
}

/// Weights by dotted name, in the training crate's layouts:
///
/// | name | shape |
/// |---|---|
/// | `time.first.weight`, `time.second.weight` | `[in, out]` |
/// | `input.weight`, `output.weight`, `*.in_conv.weight`, `*.out_conv.weight`, `*.skip.weight`, `*.value.weight`, `*.proj.weight` | `[k, C_in, C_out]` |
/// | `*.embedding.weight` | `[4C, 2C]` |
/// | `*.gamma`, `*.beta`, every `bias` | `[C]` |
/// | `attentionN.query` | `[C]` |
/// | `attentionN.key_weight` | `[C_out, C_in]` |
/// | `attentionN.rpe` | `[H, k]` |
pub type Weights = BTreeMap<String, WeightTensor>;

/// The weight `name` with `shape`, or an error naming what is missing or wrong.
pub fn get<'a>(
    weights: &'a Weights,
    name: &str,
    shape: &[usize],
) -> Result<&'a WeightTensor, ExportError> {
    let w = weights
        .get(name)
        .ok_or_else(|| ExportError::MissingWeight(name.to_string()))?;
    if w.shape != shape || w.values.len() != shape.iter().product::<usize>() {
        return Err(ExportError::WeightShape {
            name: name.to_string(),
            expected: shape.to_vec(),
            found: w.shape.clone(),
        });
    }
    Ok(w)
}
