//! FBX (binary and ASCII) to a clip, through the `ufbx` library.
//!
//! - The scene is converted on load to glTF's frame, +Y up (right-handed) and metres, with the
//!   conversion put into translations so that joints keep unit scale.
//! - The skeleton is the file's bones (limb nodes and skin-cluster bones) under a single root
//!   bone, in depth-first order. Nodes above the root (an armature, a unit scale) and between
//!   bones are folded in: each joint's transform is taken from world transforms, so pre- and
//!   post-rotations, pivots and inherit modes are all as the file means them.
//! - Names lose their namespace (`mixamorig:Hips` is `Hips`), then are made unique.
//! - The clip is one animation stack (`--clip-anim NAME|INDEX`, default the first that moves,
//!   so a Mixamo download's still `Take 001` is passed over), sampled at
//!   the file's frame rate (`--fps` overrides) from the stack's start to its end (or, for a
//!   stack that declares no range, from its first key to its last).
//! - A leaf bone that never moves (Mixamo's `_End` bones, Blender's leaf bones) becomes its
//!   parent's End Site.

use std::path::Path;

use sinmdm::motion::math::{Mat3, Vec3};
use sinmdm::motion::{ChannelClip, fps_from_frame_time};

use crate::animation::{AnimationInfo, MAX_CLIP_FRAMES, ReadOptions, choose_and_sample};
use crate::error::{FormatError, Part};
use crate::sampled::{Recorded, SampledJoints, unique_names, without_namespace};

/// A clip read from an FBX file, with what the file held besides.
#[derive(Debug, Clone)]
pub struct FbxClip {
    /// The clip, +Y up and in metres.
    pub clip: ChannelClip,
    /// The animation stack it was read from.
    pub animation: AnimationInfo,
    /// Every animation stack of the file.
    pub animations: Vec<AnimationInfo>,
    /// The length of the file's own unit in metres (0.01 for centimetres).
    pub file_unit_meters: f64,
}

/// A joint's scale may differ from its parent's by this share before the file is refused.
const SCALE_TOLERANCE: f64 = 1e-4;

/// The scene of `path`, loaded and converted to +Y up, metres, and the file's size in bytes.
fn load(path: &Path) -> Result<(ufbx::SceneRoot, usize), FormatError> {
    let bytes = crate::files::read_file(path, crate::files::FBX_LIMIT)?;
    let options = ufbx::LoadOpts {
        target_axes: ufbx::CoordinateAxes {
            right: ufbx::CoordinateAxis::PositiveX,
            up: ufbx::CoordinateAxis::PositiveY,
            front: ufbx::CoordinateAxis::PositiveZ,
        },
        target_unit_meters: 1.0,
        space_conversion: ufbx::SpaceConversion::ModifyGeometry,
        // Textures and videos packed into the file are not motion.
        ignore_embedded: true,
        temp_allocator: bounded(bytes.len()),
        result_allocator: bounded(bytes.len()),
        ..Default::default()
    };
    let scene = ufbx::load_memory(&bytes, options).map_err(|error| {
        let info = error.info();
        let detail = if info.is_empty() {
            String::new()
        } else {
            format!(" ({info})")
        };
        FormatError::bad(
            path,
            Part::Fbx,
            format!("{}{detail}", load_failure(&error, &bytes)),
        )
    })?;
    Ok((scene, bytes.len()))
}

/// The most memory ufbx may take for each of its two arenas while loading a file (1 GiB).
pub const FBX_MEMORY_LIMIT: usize = 1 << 30;
/// Below [`FBX_MEMORY_LIMIT`], each arena may take this much ...
pub const FBX_MEMORY_BASE: usize = 64 << 20;
/// ... plus this many bytes per byte of the file: far above what an FBX clip's arrays expand to
/// (compressed arrays inflate a few times), far below what a file that declares huge arrays in a
/// few bytes of zlib asks for.
pub const FBX_MEMORY_PER_BYTE: usize = 32;

/// The memory ufbx may take for each arena while loading a file of `file_bytes`.
pub fn fbx_memory_limit(file_bytes: usize) -> usize {
    FBX_MEMORY_BASE
        .saturating_add(file_bytes.saturating_mul(FBX_MEMORY_PER_BYTE))
        .min(FBX_MEMORY_LIMIT)
}

fn bounded(file_bytes: usize) -> ufbx::AllocatorOpts {
    ufbx::AllocatorOpts {
        memory_limit: fbx_memory_limit(file_bytes),
        ..Default::default()
    }
}

/// Why ufbx could not load a file, in words: its error kind said plainly where it has one, and
/// otherwise ("Failed to load", every unknown kind's text) what the file's first bytes show.
fn load_failure(error: &ufbx::Error, bytes: &[u8]) -> String {
    use ufbx::ErrorType as E;
    let what = match error.type_ {
        E::EmptyFile => "it is empty",
        E::TruncatedFile | E::TruncatedVertexStream => "it ends early: the file is cut short",
        E::UnrecognizedFileFormat => "it has neither the binary FBX header nor ASCII FBX's",
        E::UnsupportedVersion => "its FBX version is not one this reads",
        E::OutOfMemory | E::MemoryLimit | E::AllocationLimit => {
            return format!(
                "is not an FBX file this reads: it asks for more than the {} MB a file of its size may take to load (its arrays declare more data than the file holds; FBX_MEMORY_BASE + FBX_MEMORY_PER_BYTE per byte) (the FBX reader says: {})",
                fbx_memory_limit(bytes.len()) >> 20,
                error.description
            );
        }
        E::NodeDepthLimit => "it nests its nodes deeper than the reader's limit",
        E::InvalidUtf8 => "it holds a name that is not UTF-8",
        E::BadIndex => "it holds an index out of range",
        _ if bytes.starts_with(b"Kaydara FBX Binary") => {
            "it has a binary FBX header but cannot be parsed after it: damaged or cut short"
        }
        _ if is_ascii_fbx(bytes) => "it is ASCII FBX that cannot be parsed: damaged or cut short",
        _ => "it has neither the binary FBX header nor ASCII FBX's",
    };
    format!(
        "is not an FBX file this reads: {what} (the FBX reader says: {})",
        error.description
    )
}

/// Whether `bytes` open as ASCII FBX does: a `; FBX` comment or an `FBXHeaderExtension` early on.
fn is_ascii_fbx(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(4096)];
    head.starts_with(b"; FBX")
        || head
            .windows(b"FBXHeaderExtension".len())
            .any(|w| w == b"FBXHeaderExtension")
}

/// A stack's time range: the one it declares, or where it declares none, from its first key to
/// its last.
fn stack_range(stack: &ufbx::AnimStack) -> (f64, f64) {
    if stack.time_end > stack.time_begin {
        return (stack.time_begin, stack.time_end);
    }
    let (mut first, mut last) = (f64::INFINITY, f64::NEG_INFINITY);
    for layer in stack.layers.iter() {
        for value in layer.anim_values.iter() {
            for curve in value.curves.iter().flatten() {
                if !curve.keyframes.is_empty() {
                    first = first.min(curve.min_time);
                    last = last.max(curve.max_time);
                }
            }
        }
    }
    if last >= first {
        (first, last)
    } else {
        (stack.time_begin, stack.time_begin)
    }
}

/// The animation stacks of the scene.
fn stack_infos(scene: &ufbx::Scene) -> Vec<AnimationInfo> {
    scene
        .anim_stacks
        .iter()
        .enumerate()
        .map(|(index, stack)| {
            let (begin, end) = stack_range(stack);
            AnimationInfo {
                index,
                name: Some(stack.element.name.to_string()).filter(|n| !n.is_empty()),
                seconds: (end - begin).max(0.0),
                still: None,
            }
        })
        .collect()
}

/// The animation stacks of an FBX file with their lengths (for `inspect`).
pub fn list_fbx_animations(path: &Path) -> Result<Vec<AnimationInfo>, FormatError> {
    let (scene, _) = load(path)?;
    Ok(stack_infos(&scene))
}

/// The skeleton's nodes: indices into `scene.nodes` in depth-first order from the single root
/// bone, and each one's parent joint (an index into that order).
fn skeleton_nodes(
    path: &Path,
    scene: &ufbx::Scene,
) -> Result<(Vec<usize>, Vec<Option<usize>>), FormatError> {
    let count = scene.nodes.len();
    let mut is_bone = vec![false; count];
    for node in scene.nodes.iter() {
        if node.bone.is_some() && !node.is_root {
            is_bone[node.element.typed_id as usize] = true;
        }
    }
    for cluster in scene.skin_clusters.iter() {
        if let Some(bone) = &cluster.bone_node
            && !bone.is_root
        {
            is_bone[bone.element.typed_id as usize] = true;
        }
    }
    let parent_bone = |n: usize| -> Option<usize> {
        let mut at = scene.nodes[n]
            .parent
            .as_ref()
            .map(|p| p.element.typed_id as usize);
        while let Some(p) = at {
            if is_bone[p] {
                return Some(p);
            }
            at = scene.nodes[p]
                .parent
                .as_ref()
                .map(|q| q.element.typed_id as usize);
        }
        None
    };
    let roots: Vec<usize> = (0..count)
        .filter(|&n| is_bone[n] && parent_bone(n).is_none())
        .collect();
    match roots.len() {
        0 => {
            return Err(FormatError::bad(
                path,
                Part::Skeleton,
                "has no bones (no limb nodes, no skinned bones), so no skeleton".into(),
            ));
        }
        1 => {}
        _ => {
            let names: Vec<String> = roots
                .iter()
                .map(|&n| scene.nodes[n].element.name.to_string())
                .collect();
            return Err(FormatError::bad(
                path,
                Part::Skeleton,
                format!(
                    "has {} root bones ({}); a skeleton needs exactly one",
                    roots.len(),
                    names.join(", ")
                ),
            ));
        }
    }
    // Depth-first from the root, children in file order; non-bone nodes are walked through.
    let mut order = Vec::new();
    let mut stack = vec![roots[0]];
    while let Some(n) = stack.pop() {
        if is_bone[n] {
            order.push(n);
        }
        let children: Vec<usize> = scene.nodes[n]
            .children
            .iter()
            .map(|c| c.element.typed_id as usize)
            .collect();
        stack.extend(children.into_iter().rev());
    }
    let parents = order
        .iter()
        .map(|&n| parent_bone(n).and_then(|p| order.iter().position(|&o| o == p)))
        .collect();
    Ok((order, parents))
}

/// A world matrix as rotation, position and uniform scale, or `None` when its scale is not
/// uniform (or is zero).
fn decompose(m: &ufbx::Matrix) -> Option<(Mat3, Vec3, f64)> {
    let columns = [
        [m.m00, m.m10, m.m20],
        [m.m01, m.m11, m.m21],
        [m.m02, m.m12, m.m22],
    ];
    let scales = columns.map(|c| Vec3(c).norm());
    let s = scales[0];
    if !(s > 1e-12 && scales.iter().all(|v| (v - s).abs() <= SCALE_TOLERANCE * s)) {
        return None;
    }
    let rotation: Mat3 = Mat3(std::array::from_fn(|r| {
        std::array::from_fn(|c| columns[c][r] / s)
    }));
    Some((rotation, Vec3([m.m03, m.m13, m.m23]), s))
}

/// A bone's world transform in the file's rest pose: the bind pose it belongs to, else its
/// node's own (unanimated) transform. (Exporters write the pose of the current frame into the
/// nodes' own transforms; the bind pose is what a skin and BVH's zero pose mean by rest.)
fn rest_to_world(node: &ufbx::Node) -> ufbx::Matrix {
    node.bind_pose
        .as_ref()
        .and_then(|pose| {
            pose.bone_poses
                .iter()
                .find(|bone| bone.bone_node.element.typed_id == node.element.typed_id)
                .map(|bone| bone.bone_to_world)
        })
        .unwrap_or(node.node_to_world)
}

/// Each joint's rotation and translation relative to its parent joint in `scene` (a posed copy,
/// or the file's rest pose), from the nodes' world transforms: translations in world units
/// (metres), so a uniform scale above the root is folded into them. `when` says which pose in
/// messages.
fn local_transforms(
    path: &Path,
    (scene, world_of): (&ufbx::Scene, &dyn Fn(usize) -> ufbx::Matrix),
    order: &[usize],
    parents: &[Option<usize>],
    when: &str,
) -> Result<Vec<(Mat3, Vec3)>, FormatError> {
    let bad = |n: usize, message: String| {
        let name = scene.nodes[n].element.name.to_string();
        FormatError::bad(path, Part::Node(n, Some(name)), message)
    };
    let mut world: Vec<(Mat3, Vec3, f64)> = Vec::with_capacity(order.len());
    let mut local = Vec::with_capacity(order.len());
    for (j, &n) in order.iter().enumerate() {
        let (rotation, position, scale) = decompose(&world_of(n)).ok_or_else(|| {
            bad(
                n,
                format!("has a non-uniform or zero scale {when}; bones must keep their shape"),
            )
        })?;
        if !(position.iter().all(|v| v.is_finite()) && scale.is_finite()) {
            return Err(bad(n, format!("has a non-finite transform {when}")));
        }
        local.push(match parents[j] {
            None => (rotation, position),
            Some(p) => {
                let (parent_rotation, parent_position, parent_scale) = world[p];
                if (scale / parent_scale - 1.0).abs() > SCALE_TOLERANCE {
                    return Err(bad(
                        n,
                        format!(
                            "scales by {:.4} against its parent bone {when}; joints must keep unit scale",
                            scale / parent_scale
                        ),
                    ));
                }
                let inverse = parent_rotation.transpose();
                (
                    (inverse * rotation),
                    (inverse * (position - parent_position)),
                )
            }
        });
        world.push((rotation, position, scale));
    }
    Ok(local)
}

/// The clip of animation stack `chosen` (with its name) of `scene`, whose skeleton is `order`
/// with `parents`.
fn sample_stack(
    path: &Path,
    scene: &ufbx::Scene,
    (chosen, name): (usize, Option<String>),
    (order, parents): (&[usize], &[Option<usize>]),
    options: &ReadOptions,
    bytes_read: usize,
) -> Result<ChannelClip, FormatError> {
    let stack = &scene.anim_stacks[chosen];
    let part = || Part::Animation(chosen, name.clone());
    let bad = |part: Part, message: String| FormatError::bad(path, part, message);
    // Frames are sampled at the file's own rate, on its keys, and the clip reports it snapped
    // to a whole rate when within a hair of one (a BVH's 0.0333333 s frames, imported into a
    // DCC tool, come out as 30.0001 fps).
    let fps = options.fps.unwrap_or(scene.settings.frames_per_second);
    let clip_fps = match options.fps {
        Some(fps) => fps,
        None => fps_from_frame_time(1.0 / fps),
    };
    if !(fps.is_finite() && fps > 0.0) {
        return Err(bad(
            part(),
            format!("gives a frame rate of {fps}; give one (--fps)"),
        ));
    }
    let (begin, end) = stack_range(stack);
    let span = ((end - begin) * fps).round();
    if !(span.is_finite() && span >= 0.0) || span >= MAX_CLIP_FRAMES as f64 {
        return Err(bad(
            part(),
            format!(
                "runs from {begin} s to {end} s, which at {fps} fps is not 1 to {MAX_CLIP_FRAMES} frames; is the frame rate right (--fps)?"
            ),
        ));
    }
    let frames = span as usize + 1;
    let joints = order.len();
    crate::animation::check_sampled_size(path, joints, frames, bytes_read)?;
    let mut rotations = Vec::with_capacity(frames * joints);
    let mut translations = Vec::with_capacity(frames * joints);
    for f in 0..frames {
        let t = begin + f as f64 / fps;
        let posed = ufbx::evaluate_scene(scene, &stack.anim, t, ufbx::EvaluateOpts::default())
            .map_err(|error| {
                bad(
                    part(),
                    format!("could not be evaluated at {t:.3} s: {}", error.description),
                )
            })?;
        for (rotation, translation) in local_transforms(
            path,
            (&posed, &|n| posed.nodes[n].node_to_world),
            order,
            parents,
            &format!("at {t:.3} s"),
        )? {
            rotations.push(rotation);
            translations.push(translation);
        }
    }
    let rest = |n: usize| rest_to_world(&scene.nodes[n]);
    let rest_rotations = local_transforms(path, (scene, &rest), order, parents, "at rest")?
        .into_iter()
        .map(|(rotation, _)| rotation)
        .collect();

    let names = unique_names(order.iter().map(|&n| {
        let name = scene.nodes[n].element.name.to_string();
        Some(without_namespace(&name).to_string())
    }));
    let motion = SampledJoints {
        names,
        parents: parents.to_vec(),
        recorded: vec![Recorded::default(); joints],
        fps: clip_fps,
        frames,
        rotations,
        translations,
        rest_rotations,
    }
    .into_motion();
    Ok(motion.to_channels())
}

/// Reads the clip of one animation stack of an `.fbx` file.
pub fn read_fbx(path: &Path, options: &ReadOptions) -> Result<FbxClip, FormatError> {
    let (scene, bytes_read) = load(path)?;
    let mut animations = stack_infos(&scene);
    let (order, parents) = skeleton_nodes(path, &scene)?;
    let names: Vec<Option<String>> = animations.iter().map(|a| a.name.clone()).collect();
    let (chosen, clip) = choose_and_sample(
        path,
        &mut animations,
        options,
        (Part::Fbx, "animation stack"),
        |chosen| {
            let name = (chosen, names[chosen].clone());
            let skeleton = (&order[..], &parents[..]);
            sample_stack(path, &scene, name, skeleton, options, bytes_read)
        },
    )?;
    Ok(FbxClip {
        clip,
        animation: animations[chosen].clone(),
        animations,
        file_unit_meters: scene.settings.original_unit_meters,
    })
}
