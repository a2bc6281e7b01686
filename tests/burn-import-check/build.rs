//! Generates Rust code for the shipped test model with burn-onnx.

fn main() {
    let model = "../data/models/walk_tiny.onnx";
    println!("cargo:rerun-if-changed={model}");
    burn_onnx::ModelGen::new()
        .input(model)
        .out_dir("model/")
        .run_from_script();
}
