//! Adds the training clip's ground level (`layout.ground`) to a model file written before the
//! field existed, so foot planting uses the clip's ground rather than reading it from each
//! sample. The graph and every other fact stay as they are; the file is replaced atomically.
//! Usage: `cargo run --release -p sinmdm-export --example stamp_ground -- MODEL.onnx CLIP.bvh`

use std::path::Path;

use onnx_protobuf::{Message, ModelProto};
use sinmdm::bvh::read_bvh;
use sinmdm::model_file::{METADATA_KEY, ModelMetadata};
use sinmdm::motion::feet::ground_level;
use sinmdm::motion::up::to_canonical;
use sinmdm::motion::{decode, encode_for_model, global_poses};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, model_path, clip_path] = args.as_slice() else {
        return Err("usage: stamp_ground MODEL.onnx CLIP.bvh".into());
    };
    let mut model = ModelProto::parse_from_bytes(&std::fs::read(model_path)?)?;
    let entry = model
        .metadata_props
        .iter_mut()
        .find(|e| e.key == METADATA_KEY)
        .ok_or("the file has no sinmdm metadata")?;
    let mut metadata: ModelMetadata = serde_json::from_str(&entry.value)?;
    let layout = &metadata.layout;
    let clip = encode_for_model(&read_bvh(Path::new(clip_path))?, layout, None)?;
    let motion = to_canonical(&decode(layout, clip.features.view())?, layout.up);
    let ground = ground_level(
        &layout.contact_joints,
        &layout.body(),
        &global_poses(&motion),
    );
    println!(
        "{model_path}: ground {ground:.5} (was {:?})",
        metadata.layout.ground
    );
    metadata.layout.ground = Some(ground);
    entry.value = serde_json::to_string(&metadata)?;
    sinmdm::files::write_atomically(Path::new(model_path), &model.write_to_bytes()?)?;
    Ok(())
}
