//! What planting feet costs: a 100-step `generate` of 20 samples of twice the clip's length,
//! then every sample decoded raw and planted; prints the planting time against the sampling
//! time (goal: at most 10 %). Three rounds side by side; medians.
//!
//! `cargo bench -p sinmdm --bench feet [-- MODEL.onnx]` (default: the shipped walk model)

use std::ops::ControlFlow;
mod common;

use std::time::Instant;

use common::median;
use sinmdm::{Feet, Model, ModelOptions, Request, Task};

fn main() {
    let path = common::model_argument();
    let mut model = Model::open(&path, &ModelOptions::default()).expect("model");
    let frames = 2 * model.clip_frames();
    let request = Request {
        task: Task::Generate { frames },
        count: 20,
        seed: 0,
        steps: Some(100),
        feet: Feet::Planted,
        method: Default::default(),
    };
    let (mut sampling, mut raw, mut planted) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..3 {
        let t = Instant::now();
        let generated =
            sinmdm::run(&mut model, &request, &mut |_, _| ControlFlow::Continue(())).expect("run");
        sampling.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        for i in 0..generated.count() {
            std::hint::black_box(generated.raw_motion(i).expect("decode"));
        }
        raw.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        for i in 0..generated.count() {
            std::hint::black_box(generated.planted_motion(i).expect("plant"));
        }
        planted.push(t.elapsed().as_secs_f64());
    }
    let (s, r, p) = (median(&sampling), median(&raw), median(&planted));
    println!("{path}: 20 samples x {frames} frames, 100 steps (median of 3)");
    println!("  sampling           {s:8.3} s");
    println!("  decoding, raw      {r:8.3} s");
    println!("  decoding + planting {p:7.3} s");
    println!(
        "  planting adds {:.3} s: {:.2} % of the generate",
        p - r,
        100.0 * (p - r) / (s + r)
    );
}
