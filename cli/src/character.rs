//! Motions put onto the user's own character (`--mesh-from CHARACTER.glb`), retargeted when it
//! is another rig (`--retarget auto|MAP.yaml`), and what was done said in words.

use std::path::Path;

use anyhow::Result;
use clap::Args;
use sinmdm::motion::{LocalMotion, UpAxis};
use sinmdm_formats::gltf::{SpliceReport, character_bones, splice_retargeted};
use sinmdm_formats::retarget::{BoneMap, BoneMatch, Role, recognise};

/// `--retarget`: how the character's bones are matched to the motion's joints.
#[derive(Debug, Clone, Args)]
pub struct RetargetArg {
    /// For --mesh-from: match the character's bones to the motion's joints by the naming
    /// conventions both follow (`auto`: Mixamo, CMU BVH, Unreal, Unity Humanoid, Rigify) or by
    /// a map file (`MAP.yaml`, lines of `character bone: motion joint`; `auto` prints one to
    /// start from). Without it bones are matched by name, and a character with other
    /// proportions or rest pose is retargeted.
    #[arg(long, value_name = "auto|MAP.yaml", requires = "mesh_from")]
    pub retarget: Option<String>,
}

impl RetargetArg {
    /// The match asked for, its map file read and checked.
    pub fn bone_match(&self) -> Result<BoneMatch> {
        Ok(match self.retarget.as_deref() {
            None => BoneMatch::Names,
            Some("auto") => BoneMatch::Auto,
            Some(file) => {
                let path = Path::new(file);
                BoneMatch::Map(BoneMap::read(path)?, path.to_path_buf())
            }
        })
    }
}

/// Splices `motions` into `character` as `output`, and says what was done.
pub fn put_on_character(
    character: &Path,
    output: &Path,
    motions: &[(String, &LocalMotion)],
    up: UpAxis,
    bones: &BoneMatch,
) -> Result<SpliceReport> {
    let report = splice_retargeted(character, output, motions, up, bones)?;
    let plural = if report.added_animations == 1 {
        ""
    } else {
        "s"
    };
    let how = match &report.retargeted {
        Some(_) => "retargeted",
        None if report.same_frames => "its bones' frames are the model's",
        None => "its bind pose is the model's rest pose",
    };
    eprintln!(
        "wrote {}: {} with {} new animation{plural} after its {} ({:.4} of its units per the motion's; {how})",
        output.display(),
        character.display(),
        report.added_animations,
        report.kept_animations,
        report.scale,
    );
    if let Some(r) = &report.retargeted {
        eprintln!("retargeted: {}", r.reason);
        eprintln!(
            "  travel and height scaled by {:.4}, the ratio of the hips' heights above the feet at rest ({:.4} on the character, {:.4} on the motion's skeleton)",
            report.scale, r.hip_heights[0], r.hip_heights[1]
        );
        if !r.planted_feet.is_empty() {
            eprintln!(
                "  ankles kept where the motion's are, scaled (legs of other proportions bend to reach): {}",
                r.planted_feet.join(", ")
            );
        }
        if !r.still_bones.is_empty() {
            eprintln!(
                "  {} character bone{} follow no joint and keep their rest pose: {}",
                r.still_bones.len(),
                if r.still_bones.len() == 1 { "" } else { "s" },
                r.still_bones.join(", ")
            );
        }
        if !r.dropped_joints.is_empty() {
            eprintln!(
                "  {} joint{} of the motion have no bone on the character: {}",
                r.dropped_joints.len(),
                if r.dropped_joints.len() == 1 { "" } else { "s" },
                r.dropped_joints.join(", ")
            );
        }
        eprintln!(
            "  bone map (save it, edit it, and pass it back with --retarget MAP.yaml):\n{}",
            r.map.to_yaml()
        );
    }
    Ok(report)
}

/// The line `inspect` prints about a rig's bone names: the convention they follow, if any.
pub fn convention_line<'a>(names: impl IntoIterator<Item = &'a str>) -> String {
    let names: Vec<&str> = names.into_iter().collect();
    match recognise(&names) {
        Some(found) => {
            let hips = found
                .roles
                .iter()
                .position(|r| *r == Some(Role::Hips))
                .map_or("", |i| names[i]);
            format!(
                "bones      named as {} (hips '{hips}'): --retarget auto pairs them with another rig's",
                found.convention
            )
        }
        None => "bones      in no naming convention known here (Mixamo, CMU BVH, Unreal, Unity Humanoid, Rigify): to retarget, write a bone map".to_string(),
    }
}

/// `inspect` of a character file without animations: its bones and their convention.
pub fn inspect_character(path: &Path) -> Result<()> {
    let bones = character_bones(path)?;
    println!("character  {}", path.display());
    println!("           no animation: a character to put motion on (--mesh-from)");
    println!("joints     {}", bones.len());
    println!("{}", convention_line(bones.iter().map(String::as_str)));
    Ok(())
}
