//! One optimisation step: AdamW on the x0 loss of a batch, its gradients computed in shards,
//! and nothing changed when the loss or a gradient is not finite.

use burn::optim::{AdamWConfig, ModuleOptimizer};
use burn::tensor::Tensor;

use crate::config::TrainConfig;
use crate::model::{QnaUnet, on_cpu};
use crate::run::recovery::NonFinite;
use crate::run::shards::{gradients_are_finite, poison_first_gradient, sharded_gradients};

/// How one optimiser step ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepOutcome {
    /// The model was updated; the batch's loss.
    Updated(f64),
    /// Nothing was changed: the loss or a gradient was not finite.
    Skipped {
        /// The batch's loss (finite when a gradient was the problem).
        loss: f64,
        /// What was not finite.
        cause: NonFinite,
    },
}

/// The optimiser of a configuration (AdamW, epsilon 1e-8 as in PyTorch).
pub fn new_optimizer(config: &TrainConfig) -> ModuleOptimizer {
    AdamWConfig::new()
        .with_weight_decay(config.training.weight_decay as f32)
        .with_epsilon(1e-8)
        .init()
}

/// One AdamW step on the x0-prediction MSE of `model` for the batch `(x_t, t) -> x0`. Returns
/// the updated model and the loss; when the loss or any gradient is not finite the model comes
/// back unchanged (and the optimiser's state too), and the outcome says which.
///
/// The batch is cut into as many shards as rayon has threads (at least one item each), whose
/// forward and backward passes run in parallel on their own threads. burn-flex runs element-wise
/// operations on one thread, so this is what puts the other cores to work outside the matrix
/// products (docs/PERFORMANCE.md). Each shard's loss is weighted by its share of the batch, so the
/// summed gradients are those of the whole batch's mean loss; GroupNorm's statistics are per
/// item and the dropout masks are keyed by item, so nothing else depends on the split, which
/// is fixed for a given thread count (same seed and `--threads`, same run). The loss is the
/// x0 MSE.
pub fn optimisation_step(
    model: QnaUnet,
    optimizer: &mut ModuleOptimizer,
    x_t: Tensor<3>,
    t: Tensor<1>,
    x0: Tensor<3>,
    learning_rate: f64,
) -> (QnaUnet, StepOutcome) {
    step_with_fault(model, optimizer, (x_t, t, x0), learning_rate, false)
}

/// [`optimisation_step`], with the gradients poisoned first when `inject_fault` is set.
pub(crate) fn step_with_fault(
    model: QnaUnet,
    optimizer: &mut ModuleOptimizer,
    (x_t, t, x0): (Tensor<3>, Tensor<1>, Tensor<3>),
    learning_rate: f64,
    inject_fault: bool,
) -> (QnaUnet, StepOutcome) {
    // A GPU runs one batch best whole.
    let shards = if on_cpu(&x_t.device()) {
        rayon::current_num_threads()
    } else {
        1
    };
    let (loss, grads) = sharded_gradients(&model, x_t, t, x0, shards);
    let Some(mut grads) = grads else {
        let cause = NonFinite::Loss;
        return (model, StepOutcome::Skipped { loss, cause });
    };
    if inject_fault {
        poison_first_gradient(&model, &mut grads);
    }
    if !gradients_are_finite(&model, &grads) {
        let cause = NonFinite::Gradient;
        return (model, StepOutcome::Skipped { loss, cause });
    }
    (
        optimizer.step(learning_rate, model, grads),
        StepOutcome::Updated(loss),
    )
}
