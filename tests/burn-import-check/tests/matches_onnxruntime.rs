//! The burn code generated from `walk_tiny.onnx` gives onnxruntime's output.

use burn::tensor::{Int, Tensor, TensorData};
use ndarray::Array3;
use sinmdm::diffusion::noise::normals;
use sinmdm::{Model, ModelOptions};

const MODEL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../data/models/walk_tiny.onnx");

#[test]
fn generated_burn_code_matches_onnxruntime() {
    let mut reference = Model::open(MODEL, &ModelOptions { threads: Some(1) })
        .expect("the test model opens in onnxruntime (run scripts/setup.sh first)");
    let f = reference.features();
    let device = Default::default();
    let imported: burn_import_check::walk_tiny::Model =
        burn_import_check::walk_tiny::Model::default();
    for (b, n) in [(1, 23), (2, 157)] {
        let x = normals(5, n as u64, b * f * n);
        let t: Vec<i64> = (0..b as i64).map(|i| 100 + 400 * i).collect();
        let expected = reference
            .denoise(
                Array3::from_shape_vec((b, f, n), x.clone()).unwrap().view(),
                &t,
            )
            .unwrap();
        let xs = Tensor::<3>::from_data(TensorData::new(x, [b, f, n]), &device);
        let ts = Tensor::<1, Int>::from_data(TensorData::new(t, [b]), &device);
        let got = imported
            .forward(xs, ts)
            .into_data()
            .try_to_vec::<f32>()
            .unwrap();
        let scale = expected.iter().fold(0f32, |m, v| m.max(v.abs()));
        let worst = expected
            .iter()
            .zip(&got)
            .map(|(e, g)| (e - g).abs())
            .fold(0f32, f32::max);
        assert!(scale > 1e-2, "outputs are trivially small ({scale})");
        assert!(
            worst <= 1e-4,
            "B {b}, N {n}: max |diff| {worst} (outputs up to {scale})"
        );
    }
}
