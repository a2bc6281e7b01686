//! Reading parameters out by name (for export and tests), and perturbing them (for tests of
//! paths that zero-initialised layers would otherwise hide).

use std::collections::BTreeMap;

use burn::module::{Module, ModuleMapper, ModuleVisitor, Param};
use burn::tensor::{Distribution, Tensor};

use sinmdm::network::WeightTensor;

/// Every float parameter of `module` by dotted path (`block1.in_conv.weight`).
pub fn named_tensors<M: Module>(module: &M) -> BTreeMap<String, WeightTensor> {
    struct Collect {
        path: Vec<String>,
        out: BTreeMap<String, WeightTensor>,
    }
    impl ModuleVisitor for Collect {
        fn enter_module(&mut self, name: &str, _container: &str) {
            self.path.push(name.to_string());
        }
        fn exit_module(&mut self, _name: &str, _container: &str) {
            self.path.pop();
        }
        fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
            let value = param.val();
            let shape = value.dims().to_vec();
            let values = value
                .into_data()
                .convert::<f32>()
                .try_to_vec::<f32>()
                .expect("float parameter");
            let name = self
                .path
                .iter()
                .filter(|p| !p.is_empty())
                .cloned()
                .collect::<Vec<_>>()
                .join(".");
            self.out.insert(name, WeightTensor { shape, values });
        }
    }
    let mut collect = Collect {
        path: Vec::new(),
        out: BTreeMap::new(),
    };
    module.visit(&mut collect);
    collect.out
}

/// Adds `N(0, std)` noise to every float parameter (zero-initialised ones included). The
/// device must be seeded first for reproducible results.
pub fn perturb<M: Module>(module: M, std: f64) -> M {
    struct Perturb(f64);
    impl ModuleMapper for Perturb {
        fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
            let std = self.0;
            param
                .map(|t| {
                    let noise =
                        Tensor::random(t.shape(), Distribution::Normal(0.0, std), &t.device());
                    // A new leaf, so it can be tracked on an autodiff device too.
                    (t + noise).detach()
                })
                .set_require_grad(true)
        }
    }
    module.map(&mut Perturb(std))
}
