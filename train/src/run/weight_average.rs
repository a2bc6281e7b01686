//! An exponential moving average of the weights, kept beside the trained ones and exported
//! instead of them: the average of the last few thousand steps denoises more smoothly than any
//! single step's weights (see `lab/EXPERIMENTS.md`).

use burn::module::{Module, ModuleMapper, ModuleVisitor, Param};
use burn::tensor::{Tensor, TensorData};

/// The averaged values of every float parameter, in the order a module visits them.
#[derive(Debug, Clone, PartialEq)]
pub struct WeightAverage {
    decay: f64,
    updates: u64,
    values: Vec<Vec<f32>>,
}

/// Every float parameter's values, in visiting order.
fn parameter_values<M: Module>(module: &M) -> Vec<Vec<f32>> {
    struct Collect(Vec<Vec<f32>>);
    impl ModuleVisitor for Collect {
        fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
            let values = param
                .val()
                .into_data()
                .convert::<f32>()
                .try_into_vec::<f32>()
                .expect("float parameter");
            self.0.push(values);
        }
    }
    let mut collect = Collect(Vec::new());
    module.visit(&mut collect);
    collect.0
}

impl WeightAverage {
    /// An average that starts at `module`'s weights, as if it had seen `updates` steps (0 for a
    /// new run; a resumed run passes its step count so the warm-up does not restart).
    pub fn new<M: Module>(module: &M, decay: f64, updates: u64) -> WeightAverage {
        WeightAverage {
            decay,
            updates,
            values: parameter_values(module),
        }
    }

    /// The weight of the old average in the next update: `decay`, but less during the first
    /// steps, `(1 + n) / (10 + n)` after `n` updates, so the random initial weights are
    /// forgotten quickly.
    pub fn current_decay(&self) -> f64 {
        let n = self.updates as f64;
        self.decay.min((1.0 + n) / (10.0 + n))
    }

    /// Moves the average towards `module`'s current weights.
    pub fn update<M: Module>(&mut self, module: &M) {
        let decay = self.current_decay() as f32;
        let fresh = parameter_values(module);
        assert_eq!(fresh.len(), self.values.len(), "same module shape");
        for (average, new) in self.values.iter_mut().zip(&fresh) {
            for (a, &x) in average.iter_mut().zip(new) {
                *a = decay * *a + (1.0 - decay) * x;
            }
        }
        self.updates += 1;
    }

    /// `module` with the averaged weights in place of its own.
    pub fn apply<M: Module>(&self, module: M) -> M {
        struct Replace<'a> {
            values: std::slice::Iter<'a, Vec<f32>>,
        }
        impl ModuleMapper for Replace<'_> {
            fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
                let values = self.values.next().expect("same module shape").clone();
                param.map(|t| {
                    let data = TensorData::new(values, t.shape());
                    Tensor::from_data(data, &t.device())
                })
            }
        }
        module.map(&mut Replace {
            values: self.values.iter(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::ModelConfig;
    use crate::model::QnaUnet;
    use crate::model::weights::{named_tensors, perturb};
    use burn::tensor::Device;

    fn model(seed: u64) -> QnaUnet {
        let _random = crate::device_random_lock();
        let device = Device::flex();
        device.seed(seed);
        let config = ModelConfig {
            channels: 32,
            heads: 4,
            window: 3,
            dropout: 0.0,
            window_follows_fps: false,
        };
        perturb(QnaUnet::new(7, &config, &device), 0.1)
    }

    #[test]
    fn the_average_follows_the_naive_formula() {
        let (a, b, c) = (model(1), model(2), model(3));
        let mut average = WeightAverage::new(&a, 0.9, 100);
        average.update(&b);
        average.update(&c);
        // After 100 updates the warm-up no longer lowers 0.9.
        let d = 0.9f64;
        let (na, nb, nc) = (named_tensors(&a), named_tensors(&b), named_tensors(&c));
        let got = named_tensors(&average.apply(a.clone()));
        assert_eq!(got.len(), na.len());
        for (name, tensor) in &got {
            assert_eq!(tensor.shape, na[name].shape, "{name}");
            for (i, &value) in tensor.values.iter().enumerate() {
                let expected = d * d * f64::from(na[name].values[i])
                    + d * (1.0 - d) * f64::from(nb[name].values[i])
                    + (1.0 - d) * f64::from(nc[name].values[i]);
                assert!((f64::from(value) - expected).abs() < 1e-5, "{name}[{i}]");
            }
        }
    }

    #[test]
    fn the_warm_up_forgets_the_initial_weights() {
        let a = model(1);
        let mut average = WeightAverage::new(&a, 0.999, 0);
        assert!((average.current_decay() - 0.1).abs() < 1e-12);
        average.update(&model(2));
        assert!((average.current_decay() - 2.0 / 11.0).abs() < 1e-12);
        let mut late = WeightAverage::new(&a, 0.999, 1_000_000);
        assert_eq!(late.current_decay(), 0.999);
        late.update(&a);
        // Averaging a module with itself changes nothing (to rounding).
        let (same, own) = (named_tensors(&late.apply(a.clone())), named_tensors(&a));
        for (name, tensor) in &same {
            for (x, y) in tensor.values.iter().zip(&own[name].values) {
                assert!((x - y).abs() <= 1e-6 * (1.0 + y.abs()), "{name}");
            }
        }
    }
}
