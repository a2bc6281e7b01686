use burn::module::Param;
use burn::tensor::module::conv1d;
use burn::tensor::ops::ConvOptions;
use burn::tensor::{Device, Distribution, Tensor};
use std::time::Instant;

fn time<F: FnMut()>(name: &str, mut f: F) {
    f();
    let start = Instant::now();
    for _ in 0..5 {
        f();
    }
    println!("{name}: {:.1} ms", start.elapsed().as_secs_f64() * 200.0);
}

fn main() {
    let device = Device::flex().autodiff();
    let (b, c, n) = (64, 256, 200);
    let x = Tensor::<3>::random([b, c, n], Distribution::Normal(0.0, 1.0), &device).require_grad();
    let w = Param::from_tensor(Tensor::<3>::random(
        [c, c, 3],
        Distribution::Normal(0.0, 0.05),
        &device,
    ));
    let w2 = Param::from_tensor(Tensor::<2>::random(
        [c, 3 * c],
        Distribution::Normal(0.0, 0.05),
        &device,
    ));
    time("conv fwd", || {
        let _ = conv1d(x.clone(), w.val(), None, ConvOptions::new([1], [1], [1], 1)).into_data();
    });
    time("conv fwd+bwd", || {
        let y = conv1d(x.clone(), w.val(), None, ConvOptions::new([1], [1], [1], 1));
        let _ = y.sum().backward();
    });
    let unfold = |x: Tensor<3>| {
        let p = x.pad([(1, 1)], burn::tensor::ops::PadMode::Constant(0.0));
        Tensor::cat(
            vec![
                p.clone().narrow(2, 0, n),
                p.clone().narrow(2, 1, n),
                p.narrow(2, 2, n),
            ],
            1,
        )
    };
    time("mm fwd", || {
        let _ = w2
            .val()
            .unsqueeze::<3>()
            .expand([b, c, 3 * c])
            .matmul(unfold(x.clone()))
            .into_data();
    });
    time("mm fwd+bwd", || {
        let y = w2
            .val()
            .unsqueeze::<3>()
            .expand([b, c, 3 * c])
            .matmul(unfold(x.clone()));
        let _ = y.sum().backward();
    });
    // NLC layout: x [B*N, C] @ W [C, C]
    let xl =
        Tensor::<2>::random([b * n, 3 * c], Distribution::Normal(0.0, 1.0), &device).require_grad();
    let wl = Param::from_tensor(Tensor::<2>::random(
        [3 * c, c],
        Distribution::Normal(0.0, 0.05),
        &device,
    ));
    time("flat mm fwd", || {
        let _ = xl.clone().matmul(wl.val()).into_data();
    });
    time("flat mm fwd+bwd", || {
        let y = xl.clone().matmul(wl.val());
        let _ = y.sum().backward();
    });
}
