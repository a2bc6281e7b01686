// The Rust snippet of README.md, section "In an engine", kept here so that a test can compile it.
// The lines between the outer braces are the README's code block, line for line: change both
// together. The braces make the file one block expression, the body of a function
//     fn readme_engine_snippet() -> Result<Vec<sinmdm::Pose>, Box<dyn std::error::Error>>
// so a test can write that signature followed by `{ include!("PATH/TO/docs/readme_engine_snippet.rs") }`.
// The model path is relative to the repository root (where the README's commands run); a test
// that also runs it from a crate's folder must change to the root first.
{
use sinmdm::{Feet, Method, Model, ModelOptions, Request, Task};

let mut model = Model::open("onnx-models/human_walk_cmu.onnx", &ModelOptions::default())?;
let request = Request {
    task: Task::Generate { frames: 300 }, // 10 s at the model's 30 fps
    count: 4,                             // a crowd: four different walks in one batch
    seed: 7,                              // same model, seed and request: same motion
    steps: Some(sinmdm::DEFAULT_STEPS),   // 50 denoising steps
    feet: Feet::Planted,                  // contact points held still on the ground
    method: Method::Ancestral,            // the paper's sampler
};
// All at once (the callback sees each step and may stop the run):
//   let crowd = sinmdm::run(&mut model, &request, &mut |_, _| std::ops::ControlFlow::Continue(()))?;
// In a game, an owned run (Send + 'static) takes a few steps per frame, same bits:
let mut run = sinmdm::plan(model.metadata(), &request)?.start()?;
while !run.step(&mut model, 3)?.is_finished() {
    // yield to the frame loop here; dropping `run` cancels it
}
let crowd = run.finish()?;
let poses = crowd.poses(0)?; // per frame: root position, local rotations (x, y, z, w), translations
Ok(poses)
}
