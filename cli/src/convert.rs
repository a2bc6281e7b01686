//! `sinmdm convert`: a clip from one motion format to another (BVH, glTF), so a clip can go
//! into an engine, or a glTF clip into a BVH tool, without a DCC round trip.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sinmdm::motion::up::to_canonical;
use sinmdm::motion::up_detect::choose_up;
use sinmdm::motion::{UpAxis, global_poses, skeleton_height};

use crate::clip_files::{
    GltfPlacement, is_gltf, metres_per_unit, read_motion_file, write_motion_file,
};

pub(crate) const EXAMPLES: &str = "Examples:
  sinmdm convert tests/data/bvh/human_walk_cmu_131_01.bvh -o walk.glb   # for an engine
  sinmdm convert character.glb --clip-anim Walk -o walk.bvh             # one animation as BVH
  sinmdm convert walk.bvh -o walk.glb --unit-scale 0.01                 # the file is in cm
  sinmdm convert dance.fbx -o michelle.glb --mesh-from Michelle.glb      # onto a character
  sinmdm convert walk.bvh -o hero.glb --mesh-from hero.glb --retarget auto  # other bone names

glTF is written in metres with +Y up (the clip's up axis is read from the motion, --up
overrides; its unit from the skeleton's height, --unit-scale overrides); BVH keeps the clip's
own frame and units. FBX is not written.";

/// Arguments of `sinmdm convert`.
#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// The clip (.bvh, .glb, .gltf, .fbx).
    pub clip: PathBuf,
    /// The file to write (.bvh, .glb, .gltf; FBX is read but not written: write .glb).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    #[command(flatten)]
    pub read: crate::clip_files::ClipUpArg,
    /// Metres per file unit, for glTF output (default: from the skeleton's height).
    #[arg(long, value_name = "METRES")]
    pub unit_scale: Option<f64>,
    /// Add a one-triangle mesh skinned to the root (glTF output), for importers that build
    /// skeletons only from skinned meshes (Unreal's).
    #[arg(long)]
    pub proxy_mesh: bool,
    /// The character's own .glb: the output (a .glb) is that file with the clip appended as
    /// one more animation of its bones (matched by name, or as --retarget says; a rig of other
    /// proportions or rest pose is retargeted).
    #[arg(long, value_name = "CHARACTER.glb")]
    pub mesh_from: Option<PathBuf>,
    #[command(flatten)]
    pub retarget: crate::character::RetargetArg,
}

pub(crate) fn run(args: &ConvertArgs) -> Result<()> {
    crate::clip_files::check_output(&args.output)?;
    let clip = read_motion_file(&args.clip, args.read.clip_anim.as_deref())?;
    let motion = clip.to_local();
    let name = args
        .clip
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned());
    if let Some(character) = &args.mesh_from {
        anyhow::ensure!(
            is_gltf(&args.output)
                && args
                    .output
                    .extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("glb")),
            "--mesh-from writes the character's file with the clip added: -o must be a .glb"
        );
        anyhow::ensure!(
            args.unit_scale.is_none() && !args.proxy_mesh,
            "--mesh-from takes the character's units and meshes; leave out --unit-scale and --proxy-mesh"
        );
        let bones = args.retarget.bone_match()?;
        let (up, detection) = choose_up(&motion, args.read.up);
        if let Some(found) = detection {
            eprintln!("{}: up axis {}", args.clip.display(), found.describe());
        }
        let named = [(name.unwrap_or_else(|| "clip".into()), &motion)];
        crate::character::put_on_character(character, &args.output, &named, up, &bones)?;
        return Ok(());
    }
    let (up, metres) = if is_gltf(&args.output) {
        let (up, detection) = choose_up(&motion, args.read.up);
        if let Some(found) = detection {
            eprintln!("{}: up axis {}", args.clip.display(), found.describe());
        }
        let height = skeleton_height(&global_poses(&to_canonical(&motion, up)));
        (up, metres_per_unit(height, args.unit_scale)?)
    } else {
        anyhow::ensure!(
            args.unit_scale.is_none(),
            "--unit-scale is for glTF output; BVH keeps the clip's units"
        );
        (UpAxis::PosY, 1.0)
    };
    let placement = GltfPlacement {
        up,
        metres,
        proxy_mesh: args.proxy_mesh,
    };
    write_motion_file(
        &args.output,
        std::slice::from_ref(&motion),
        name.as_deref(),
        placement,
    )?;
    eprintln!(
        "wrote {} ({} joints, {} frames at {} fps)",
        args.output.display(),
        motion.skeleton.len(),
        motion.frame_count(),
        motion.fps
    );
    Ok(())
}
