//! A training step's batch cut into shards, one thread each, with the gradients summed: burn's
//! CPU backend runs element-wise operations on one thread, so this puts the other cores to work.

use burn::module::{Module, ModuleMapper, ModuleVisitor, Param};
use burn::optim::GradientsParams;
use burn::tensor::{Device, Distribution, Tensor};

use crate::model::QnaUnet;
use crate::model::dropout::DropoutKey;
use crate::run::loss::x0_loss;

/// The batch's mean loss and its gradients (none when the loss is not finite), computed in
/// `shards` shards on as many threads. The loss is the x0 MSE.
pub(crate) fn sharded_gradients(
    model: &QnaUnet,
    x_t: Tensor<3>,
    t: Tensor<1>,
    x0: Tensor<3>,
    shards: usize,
) -> (f64, Option<GradientsParams>) {
    let batch = x_t.dims()[0];
    let seed = dropout_seed(&x_t.device());
    let shards = shard_ranges(batch, shards);
    let shard_step = |&(first, len): &(usize, usize)| {
        // Each shard differentiates its own leaves (same parameter ids and values): shards
        // sharing leaf nodes share one autodiff tape, which the first backward pass consumes.
        let model = model.clone().map(&mut FreshLeaves);
        let key = DropoutKey {
            seed,
            first_item: first,
        };
        let timesteps = t.clone().narrow(0, first, len);
        let prediction = model.forward_training(
            x_t.clone().narrow(0, first, len),
            timesteps.clone(),
            Some(key),
        );
        let target = x0.clone().narrow(0, first, len);
        let loss = x0_loss(&prediction, &target);
        let share = len as f64 / batch as f64;
        let value = f64::from(loss.clone().into_scalar::<f32>()) * share;
        if !value.is_finite() {
            return (value, None);
        }
        let grads = GradientsParams::from_grads((loss * share).backward(), &model);
        (value, Some(grads))
    };
    // Plain threads, not rayon tasks: a shard blocks on burn's graph lock, and a rayon worker
    // blocked there could be the one another shard's matrix product is waiting for.
    let results: Vec<(f64, Option<GradientsParams>)> = std::thread::scope(|scope| {
        let others: Vec<_> = shards[1..]
            .iter()
            .map(|shard| scope.spawn(move || shard_step(shard)))
            .collect();
        let mut results = vec![shard_step(&shards[0])];
        results.extend(
            others
                .into_iter()
                .map(|handle| handle.join().expect("a training shard panicked")),
        );
        results
    });
    let value: f64 = results.iter().map(|(v, _)| v).sum();
    if !value.is_finite() {
        return (value, None);
    }
    let mut parts = results.into_iter().filter_map(|(_, g)| g);
    let mut grads = parts.next().expect("a batch has at least one shard");
    for part in parts {
        model.visit(&mut AddGradients {
            total: &mut grads,
            part,
        });
    }
    (value, Some(grads))
}

/// Whether every gradient in `grads` (those of `model`'s parameters) is finite. A tensor's sum
/// is NaN or infinite when any of its values is (or when the values overflow f32 together,
/// which no update should follow either).
pub(crate) fn gradients_are_finite(model: &QnaUnet, grads: &GradientsParams) -> bool {
    struct Check<'a> {
        grads: &'a GradientsParams,
        finite: bool,
    }
    impl ModuleVisitor for Check<'_> {
        fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
            if !self.finite {
                return;
            }
            if let Some(grad) = self.grads.get::<D>(param.id) {
                let sum = grad.sum().into_scalar::<f32>();
                self.finite = sum.is_finite();
            }
        }
    }
    let mut check = Check {
        grads,
        finite: true,
    };
    model.visit(&mut check);
    check.finite
}

/// Turns the gradient of `model`'s first parameter into NaN: a fault injected by tests of the
/// recovery path, so they exercise the same check a real failure meets.
pub(crate) fn poison_first_gradient(model: &QnaUnet, grads: &mut GradientsParams) {
    struct Poison<'a> {
        grads: &'a mut GradientsParams,
        done: bool,
    }
    impl ModuleVisitor for Poison<'_> {
        fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
            if self.done {
                return;
            }
            if let Some(grad) = self.grads.remove::<D>(param.id) {
                self.grads.register(param.id, grad.mul_scalar(f32::NAN));
                self.done = true;
            }
        }
    }
    model.visit(&mut Poison { grads, done: false });
}

/// `(first item, items)` of each shard of a batch split `threads` ways, larger shards first.
fn shard_ranges(batch: usize, threads: usize) -> Vec<(usize, usize)> {
    let shards = threads.clamp(1, batch.max(1));
    let (size, extra) = (batch / shards, batch % shards);
    let mut first = 0;
    (0..shards)
        .map(|i| {
            let len = size + usize::from(i < extra);
            first += len;
            (first - len, len)
        })
        .collect()
}

/// The dropout seed of a step, from the device generator (which the trainer seeds every step).
fn dropout_seed(device: &Device) -> u64 {
    let draw = Tensor::<1>::random([2], Distribution::Default, device)
        .into_data()
        .try_to_vec::<f32>()
        .expect("f32 draw");
    (u64::from(draw[0].to_bits()) << 32) | u64::from(draw[1].to_bits())
}

/// Replaces every parameter's autodiff node with a new leaf of the same id and value.
struct FreshLeaves;

impl ModuleMapper for FreshLeaves {
    fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
        param.map(|tensor| tensor.detach().require_grad())
    }
}

/// Adds the gradients of `part` to `total`, parameter by parameter.
struct AddGradients<'a> {
    total: &'a mut GradientsParams,
    part: GradientsParams,
}

impl ModuleVisitor for AddGradients<'_> {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        if let Some(grad) = self.part.remove::<D>(param.id) {
            let sum = match self.total.remove::<D>(param.id) {
                Some(total) => total + grad,
                None => grad,
            };
            self.total.register(param.id, sum);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TrainConfig;
    use crate::model::QnaUnet;
    use crate::model::weights::perturb;
    use burn::tensor::Distribution;
    use burn::tensor::TensorData;

    #[test]
    fn shards_split_batches_evenly_with_larger_ones_first() {
        assert_eq!(shard_ranges(4, 1), vec![(0, 4)]);
        assert_eq!(shard_ranges(4, 3), vec![(0, 2), (2, 1), (3, 1)]);
        assert_eq!(shard_ranges(2, 8), vec![(0, 1), (1, 1)]);
    }

    #[test]
    fn sharded_gradients_equal_the_whole_batch_gradients() {
        // The tiny network with dropout on and perturbed weights (so no gradient is trivially
        // zero), the whole batch against uneven shards: the same loss and gradients.
        let mut config: TrainConfig =
            TrainConfig::parse(include_str!("../../../configs/tiny.yaml")).unwrap();
        config.model.dropout = 0.5;
        let _random = crate::device_random_lock();
        let device = Device::flex().autodiff();
        device.seed(4);
        let (batch, f, n) = (5, 12, 30);
        let model = perturb(QnaUnet::new(f, &config.model, &device), 0.2);
        let normal = Distribution::Normal(0.0, 1.0);
        let x_t = Tensor::<3>::random([batch, f, n], normal, &device);
        let x0 = Tensor::<3>::random([batch, f, n], normal, &device);
        let t = Tensor::<1>::from_data(
            TensorData::new(vec![3.0f32, 400.0, 999.0, 20.0, 650.0], [batch]),
            &device,
        );
        let gradients = |shards| {
            device.seed(9);
            let (loss, grads) =
                sharded_gradients(&model, x_t.clone(), t.clone(), x0.clone(), shards);
            (loss, grads.expect("finite loss"))
        };
        let (whole_loss, whole) = gradients(1);
        let (split_loss, split) = gradients(3);
        assert!(
            (whole_loss - split_loss).abs() < 1e-6 * whole_loss,
            "{whole_loss} {split_loss}"
        );
        struct Compare<'a>(&'a GradientsParams, &'a GradientsParams, usize);
        impl ModuleVisitor for Compare<'_> {
            fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
                let read = |g: &GradientsParams| {
                    g.get::<D>(param.id)
                        .expect("every parameter has a gradient")
                        .into_data()
                        .try_to_vec::<f32>()
                        .unwrap()
                };
                let (a, b) = (read(self.0), read(self.1));
                let scale = a.iter().fold(0f32, |m, v| m.max(v.abs()));
                let worst = a
                    .iter()
                    .zip(&b)
                    .map(|(x, y)| (x - y).abs())
                    .fold(0f32, f32::max);
                assert!(
                    worst <= 1e-4 * scale + 1e-7,
                    "max |diff| {worst}, scale {scale}"
                );
                // Softmax ignores a constant added to every score, so the key bias has a zero
                // gradient up to rounding; the absolute term covers it.
                self.2 += usize::from(scale > 1e-6);
            }
        }
        let mut compare = Compare(&whole, &split, 0);
        model.visit(&mut compare);
        assert!(compare.2 > 20, "only {} tensors have gradients", compare.2);
    }
}
