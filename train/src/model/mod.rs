//! The QnA-UNet denoiser in burn: timestep embedding, residual blocks, QnA attention.

pub mod dropout;
pub mod layers;
pub mod pointwise;
pub mod qna;
pub mod resblock;
pub mod timestep;
pub mod unet;
pub mod weights;

use burn::module::{Module, ModuleVisitor, Param};

use burn::tensor::{Device, Tensor};

pub use unet::QnaUnet;

pub use sinmdm::network::NORM_GROUPS;

/// GroupNorm with the contract's groups and epsilon and affine weights, over `[B, N, C]`.
pub(crate) fn group_norm(channels: usize, device: &Device) -> layers::ChannelNorm {
    layers::ChannelNorm::new(
        NORM_GROUPS,
        channels,
        f64::from(sinmdm::network::NORM_EPSILON),
        device,
    )
}

/// Whether `device` is the CPU backend (with or without autodiff), where the workarounds for its
/// single-threaded element-wise operations pay off.
pub(crate) fn on_cpu(device: &Device) -> bool {
    device.clone().inner() == Device::flex()
}

/// Draws every lazily initialised parameter now, in module order, so the weights depend only on
/// the seed and not on the order of later tensor operations.
pub(crate) fn materialize<M: Module>(module: &M) {
    struct Touch;
    impl ModuleVisitor for Touch {
        fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
            let _ = param.val();
        }
    }
    module.visit(&mut Touch);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cpu_device_is_recognised() {
        assert!(on_cpu(&Device::flex()));
        assert!(on_cpu(&Device::flex().autodiff()));
    }
}
