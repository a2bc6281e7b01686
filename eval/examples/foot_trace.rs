//! One contact joint of one saved sample, frame by frame, as the network made it and as
//! planting writes it: its label, its contact point, the distance from the chain's top to it,
//! and the chain's middle joint (the knee of a hip-knee-ankle chain; named in the header), in
//! skeleton heights in the canonical frame: what the sweep's acceleration figures count, to
//! look at. Usage:
//! `cargo run --release -p sinmdm-eval --example foot_trace -- MODEL.onnx SAMPLES.json CONTACT FROM TO`
//! (SAMPLES.json from `sinmdm generate --feet raw --features-json`; CONTACT indexes the model's
//! contact joints; the first sample is traced).

use std::path::Path;

use sinmdm::features_file::read_features;
use sinmdm::motion::feet::{Kept, PlantOptions, leg_chain, plant_feet};
use sinmdm::motion::math::Vec3;
use sinmdm::motion::up::to_canonical;
use sinmdm::motion::{decode, global_poses};
use sinmdm::{Model, ModelOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 6 {
        return Err("usage: foot_trace MODEL.onnx SAMPLES.json CONTACT FROM TO".into());
    }
    let model = Model::open(&args[1], &ModelOptions::default())?;
    let layout = &model.metadata().layout;
    let (features, _) = read_features(Path::new(&args[2]))?;
    let (contact, from, to): (usize, usize, usize) =
        (args[3].parse()?, args[4].parse()?, args[5].parse()?);
    let sample = features.outer_iter().next().ok_or("no sample")?;
    let motion = decode(layout, sample)?;
    let labels = layout.contact_labels(sample);
    let options = PlantOptions::default();
    let (planted, _) = plant_feet(layout, &motion, &labels, &Kept::default(), &options)?;
    let joint = *layout
        .contact_joints
        .get(contact)
        .ok_or("no such contact")?;
    let chain = leg_chain(&layout.skeleton, &layout.rest_translations, joint).ok_or("no chain")?;
    let (top, knee) = (chain.joints[0], chain.joints[chain.joints.len() / 2]);
    let h = layout.skeleton_height;
    let raw = global_poses(&to_canonical(&motion, layout.up));
    let out = global_poses(&to_canonical(&planted, layout.up));
    let at = |v: Vec3| format!("{:7.3} {:7.3} {:7.3}", v[0] / h, v[1] / h, v[2] / h);
    let middle = &layout.skeleton.joints[knee].name;
    println!(
        "frame | label | point raw | point planted | top to point, planted | {middle} raw | {middle} planted"
    );
    for f in from..to.min(raw.len()) {
        println!(
            "{f} | {:.2} | {} | {} | {:.3} | {} | {}",
            labels[contact][f],
            at(raw[f].contact_point(joint)),
            at(out[f].contact_point(joint)),
            (out[f].contact_point(joint) - out[f].joints[top]).norm() / h,
            at(raw[f].joints[knee]),
            at(out[f].joints[knee]),
        );
    }
    Ok(())
}
