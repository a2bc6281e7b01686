//! Plain named weights: the only thing the exporter needs from training.

use sinmdm::network::{WeightTensor, Weights};

use crate::ExportError;

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
