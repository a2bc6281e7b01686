//! `sinmdm inspect`: what the model will see of a clip.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Args;

use sinmdm::bvh::write_bvh;

use crate::clip_files::read_motion_file_and_source;
use sinmdm::files::write_atomically;
use sinmdm::motion::up::{UP, file_axis_name};
use sinmdm::motion::{
    ChannelClip, ContactConfig, EncodeOptions, EncodedClip, FeatureLayout, Skeleton, decode,
    encode, fk, global_poses, math, max_position_error, skeleton::Channel,
};

pub(crate) const EXAMPLES: &str = "Examples:
  sinmdm inspect tests/data/bvh/human_walk_cmu_131_01.bvh
  sinmdm inspect walk.bvh --fps 30 --roundtrip walk_30fps.bvh
  sinmdm inspect dog.bvh --contact-joints LeftHand,RightHand,LeftFoot,RightFoot
  sinmdm inspect zup_clip.bvh --up z";

/// Arguments of `sinmdm inspect`.
#[derive(Debug, Args)]
pub struct InspectArgs {
    /// The clip: .bvh, .glb, .gltf or .fbx.
    pub clip: PathBuf,
    /// Frame rate of the features (default: the clip's own).
    #[arg(long)]
    pub fps: Option<f64>,
    /// Encode the clip to features, decode them and write the result as BVH here.
    #[arg(long, value_name = "OUT.bvh")]
    pub roundtrip: Option<PathBuf>,
    /// Write every joint's global position per frame as JSON here (for checking against other tools).
    #[arg(long, value_name = "OUT.json")]
    pub positions: Option<PathBuf>,
    /// Contact joints, comma-separated (default: chosen automatically).
    #[arg(long, value_delimiter = ',')]
    pub contact_joints: Option<Vec<String>>,
    /// Contact speed threshold in skeleton heights per second.
    #[arg(long, default_value_t = ContactConfig::default().speed_threshold)]
    pub contact_speed: f64,
    /// How the root is described: `world` (ground displacement in world axes) or `heading`
    /// (speeds and turn in the character's facing frame).
    #[arg(long, default_value = "world", value_name = "LAYOUT")]
    pub root: sinmdm::motion::RootLayout,
    #[command(flatten)]
    pub up: crate::clip_files::ClipUpArg,
}

/// A plain-words guess of the file's length unit from the skeleton height.
pub fn units_guess(height: f64) -> &'static str {
    match height {
        h if (0.3..=3.0).contains(&h) => "metres (a 0.3-3 m tall figure)",
        h if (30.0..=300.0).contains(&h) => "centimetres (a 30-300 cm tall figure)",
        h if (3.0..30.0).contains(&h) => {
            "unknown: decimetres, inches or CMU units (about 0.056 m); the model does not care"
        }
        _ => "unknown; the model does not care (features are standardised)",
    }
}

pub(crate) fn run(args: &InspectArgs) -> Result<()> {
    if let Some(fps) = args.fps
        && !(fps.is_finite() && fps > 0.0)
    {
        bail!("--fps must be a positive number, got {fps}");
    }
    // The file is read once: its animations come with the clip. Only a glTF file that could not
    // be read as a clip is asked whether it is a character without animations (for
    // --mesh-from), so a clip is not read twice.
    let (clip, source) = match read_motion_file_and_source(&args.clip, args.up.clip_anim.as_deref())
    {
        Ok(read) => read,
        Err(error) => {
            if crate::clip_files::is_gltf(&args.clip)
                && sinmdm_formats::list_animations(&args.clip).is_ok_and(|a| a.is_empty())
            {
                return crate::character::inspect_character(&args.clip);
            }
            return Err(error);
        }
    };
    print_animations(&source.animations);
    let options = EncodeOptions {
        fps: args.fps,
        contacts: ContactConfig {
            joints: args.contact_joints.clone(),
            speed_threshold: args.contact_speed,
            ..ContactConfig::default()
        },
        up: args.up.up,
        root: args.root,
    };
    let encoded = encode(&clip, &options)
        .with_context(|| format!("{}: cannot encode the clip", args.clip.display()))?;
    print!("{}", describe(args, &clip, &encoded));
    if let Some(path) = &args.positions {
        let json = positions_json(&clip)?;
        write_atomically(path, json.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
        println!("\npositions  written to {}", path.display());
    }
    if let Some(path) = &args.roundtrip {
        write_roundtrip(path, &clip, &encoded)?;
    }
    Ok(())
}

/// The file's animations, marking those in which nothing moves.
fn print_animations(animations: &[sinmdm_formats::AnimationInfo]) {
    if animations.is_empty() {
        return;
    }
    println!("animations {}", animations.len());
    for a in animations {
        let still = match a.still {
            Some(true) => " (still: nothing moves)",
            _ => "",
        };
        println!(
            "  {} {:.2} s{still}",
            crate::clip_files::describe_animation(a),
            a.seconds
        );
    }
}

/// What the model will see of the clip: its frames, joints, up axis, units, root, facing,
/// contacts and features, then the joint table.
fn describe(args: &InspectArgs, clip: &ChannelClip, encoded: &EncodedClip) -> String {
    let layout = &encoded.layout;
    let skeleton = &clip.skeleton;
    let frames = clip.frame_count();
    let mut out = String::new();
    let _ = writeln!(out, "clip       {}", args.clip.display());
    let _ = writeln!(
        out,
        "frames     {frames} at {} fps ({:.2} s); features at {} fps: {} frames",
        trim_float(clip.fps),
        (frames.max(1) - 1) as f64 / clip.fps,
        trim_float(layout.fps),
        encoded.features.ncols()
    );
    let end_sites = skeleton
        .joints
        .iter()
        .filter(|j| j.end_site.is_some())
        .count();
    let _ = writeln!(
        out,
        "joints     {} ({end_sites} End Sites), {} channels per frame",
        skeleton.len(),
        skeleton.channel_count()
    );
    let _ = writeln!(
        out,
        "{}",
        crate::character::convention_line(skeleton.joints.iter().map(|j| j.name.as_str()))
    );
    let up_line = match &encoded.up_detection {
        Some(found) => format!("{} (read from the motion)", found.describe()),
        None => format!("{} (given with --up)", layout.up),
    };
    let _ = writeln!(out, "up         {up_line}");
    let height = layout.skeleton_height;
    let _ = writeln!(out, "height     {height:.3} file units along {}", layout.up);
    let _ = writeln!(out, "units      {}", units_guess(height));
    let _ = writeln!(out, "root       {}", root_line(layout, skeleton));
    if let Some(h) = layout.root.as_ref().and_then(|r| r.heading.as_ref()) {
        let _ = writeln!(out, "facing     {}", facing_line(h, skeleton));
    }
    let _ = writeln!(
        out,
        "cycle      {}",
        if encoded.in_place {
            "in-place cycle: the root does not travel, so contacts are measured against the treadmill (the feet's common backward drift)"
        } else {
            "travels (or stands): contacts from speed over the ground"
        }
    );
    let contacts: Vec<String> = layout
        .contact_joints
        .iter()
        .zip(&encoded.contact_share)
        .map(|(&j, share)| format!("{} {:.0}%", skeleton.joints[j].name, share * 100.0))
        .collect();
    let _ = writeln!(
        out,
        "contacts   {} (in contact while slower than {} heights/s)",
        if contacts.is_empty() {
            "none".to_string()
        } else {
            contacts.join(", ")
        },
        layout.contact_speed_threshold
    );
    let root_width = layout.root.as_ref().map_or(0, |r| r.width());
    let _ = writeln!(
        out,
        "features   F = {} = root {} + rotations {}x6 + positions {} + contacts {}",
        layout.width(),
        root_width,
        layout.rotation_joints.len(),
        layout.position_channels.len(),
        layout.contact_joints.len()
    );
    out.push_str(&joint_table(skeleton));
    out
}

/// The root's joint and feature axes, or that it has no position channels.
fn root_line(layout: &FeatureLayout, skeleton: &Skeleton) -> String {
    let Some(root) = &layout.root else {
        return "no position channels: the clip stays in place".into();
    };
    let axes: Vec<String> = if root.heading.is_some() {
        let up = file_axis_name(layout.up, UP);
        vec![
            "forward".into(),
            "leftward".into(),
            "turn".into(),
            format!("height({up})"),
        ]
    } else {
        root.axes
            .iter()
            .map(|a| {
                let name = file_axis_name(layout.up, a.index());
                if a.index() == UP {
                    format!("height({name})")
                } else {
                    format!("d{name}")
                }
            })
            .collect()
    };
    let s = root.start_position;
    format!(
        "{} -> {} (start {:.3} {:.3} {:.3}, canonical Y-up)",
        skeleton.joints[root.joint].name,
        axes.join(" "),
        s[0],
        s[1],
        s[2]
    )
}

/// How a heading-relative root reads the facing: across which joints, told apart by what.
fn facing_line(h: &sinmdm::motion::features::Heading, skeleton: &Skeleton) -> String {
    use sinmdm::motion::features::heading::SideEvidence;
    format!(
        "across {} (left) and {} (right), sides told by {}, smoothed over {} s; starts at {:.1} degrees",
        skeleton.joints[h.left].name,
        skeleton.joints[h.right].name,
        match h.sides {
            SideEvidence::Names => "their names",
            SideEvidence::Travel => "the travel (forward is where the clip goes)",
            SideEvidence::Unresolved =>
                "nothing: neither names nor travel say, so forward may be the back",
        },
        h.smoothing,
        h.start.to_degrees()
    )
}

/// Every joint with its parent and channels, one line each under a header.
fn joint_table(skeleton: &Skeleton) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "\n  #  joint                      parent                     channels"
    );
    for (i, joint) in skeleton.joints.iter().enumerate() {
        let parent = joint
            .parent
            .map_or("-", |p| skeleton.joints[p].name.as_str());
        let channels: Vec<&str> = joint.channels.iter().map(|c| short_channel(*c)).collect();
        let _ = writeln!(
            out,
            "{i:>3}  {:<26} {:<26} {}",
            joint.name,
            parent,
            channels.join(" ")
        );
    }
    out
}

/// Writes the clip encoded and decoded again as BVH, with the largest position error when the
/// frame rate is the clip's own.
fn write_roundtrip(
    path: &std::path::Path,
    clip: &ChannelClip,
    encoded: &EncodedClip,
) -> Result<()> {
    let layout = &encoded.layout;
    let motion = decode(layout, encoded.features.view())?;
    let written = motion.to_channels();
    write_bvh(path, &written)?;
    print!(
        "\nroundtrip  written to {} at {} fps",
        path.display(),
        trim_float(layout.fps)
    );
    if (layout.fps - clip.fps).abs() < 1e-9 {
        let worst = max_position_error(&clip.to_local(), &written.to_local())
            .context("the round trip changed the frame or joint count")?;
        println!(
            "; largest joint position error {:.2e} x height",
            worst / layout.skeleton_height.max(1e-12)
        );
    } else {
        println!();
    }
    Ok(())
}

/// Global joint positions of every frame as JSON: `{"fps", "joints": [names], "positions":
/// [frame][joint][xyz]}`.
fn positions_json(clip: &sinmdm::motion::ChannelClip) -> Result<String> {
    let poses = global_poses(&clip.to_local());
    let positions: Vec<&Vec<math::Vec3>> =
        poses.iter().map(|p: &fk::GlobalPose| &p.joints).collect();
    let names: Vec<&str> = clip
        .skeleton
        .joints
        .iter()
        .map(|j| j.name.as_str())
        .collect();
    Ok(serde_json::to_string(&serde_json::json!({
        "fps": clip.fps,
        "joints": names,
        "positions": positions,
    }))?)
}

fn short_channel(c: Channel) -> &'static str {
    match c {
        Channel::Position(sinmdm::motion::Axis::X) => "Xpos",
        Channel::Position(sinmdm::motion::Axis::Y) => "Ypos",
        Channel::Position(sinmdm::motion::Axis::Z) => "Zpos",
        Channel::Rotation(sinmdm::motion::Axis::X) => "Xrot",
        Channel::Rotation(sinmdm::motion::Axis::Y) => "Yrot",
        Channel::Rotation(sinmdm::motion::Axis::Z) => "Zrot",
    }
}

fn trim_float(v: f64) -> String {
    if v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.3}")
    }
}
