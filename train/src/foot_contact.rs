//! The foot-contact term of the training loss: where the clip's contact label says a foot is on
//! the ground, the predicted motion's contact point should not move.
//!
//! The network predicts the clean motion x0, so its contact points can be found by forward
//! kinematics of that prediction, as a differentiable function of it: the 6D rotations of the
//! joints on the way from the root to each contact joint, the bone offsets, the root's height
//! and its displacement per frame. A contact point's velocity between two frames is the root's
//! displacement plus the change of the point relative to the root. The term is the mean, over
//! frame pairs and contact joints, of the squared speed (in skeleton heights per second)
//! weighted by the clip's label at both frames; `training.foot_contact_weight` scales it.
//!
//! Velocities do not change under a fixed rotation or translation of the whole body, so the
//! kinematics run in the canonical (Y-up) frame from the joint that carries the root's travel,
//! and whatever is above that joint (a static container, the file's up axis) is left out.
//!
//! The joints are processed a tree level at a time, every joint of a level in one tensor
//! operation (both legs of a human, all four of a dog), so the term adds a few dozen
//! operations to a step whatever the skeleton.

use burn::tensor::{Device, Int, Tensor, TensorData};
use sinmdm::motion::math::{IDENTITY, Mat3, Vec3};
use sinmdm::motion::up::UP;
use sinmdm::motion::{ColumnKind, FeatureLayout, Normalizer};

/// A joint on the way to a contact point.
#[derive(Debug, Clone)]
struct Link {
    /// Its translation from its parent at rest, and the feature rows (row, component) that
    /// replace components of it.
    translation: (Vec3, Vec<(usize, usize)>),
}

/// The joints at one depth below the top joint.
#[derive(Debug, Clone)]
struct Level {
    /// The links, by index.
    links: Vec<usize>,
    /// Each link's parent, as its place in the level above.
    parents: Vec<usize>,
    /// The contact points on this level: (contact index, place in this level, End Site).
    contacts: Vec<(usize, usize, Vec3)>,
}

/// The foot-contact term of one clip's layout (see the module's documentation).
#[derive(Debug, Clone)]
pub struct FootContact {
    links: Vec<Link>,
    /// The first of the six feature rows of each link with a rotation feature, by link.
    rotating: Vec<(usize, usize)>,
    /// The fixed rotation of each link without one, by link.
    fixed: Vec<(usize, Mat3)>,
    /// Levels from the top joint (level 0, alone) down.
    levels: Vec<Level>,
    /// Each contact joint's label row, in the layout's contact order.
    label_rows: Vec<usize>,
    /// Feature rows of the root's displacement per frame, with the component each moves.
    travel: Vec<(usize, usize)>,
    mean: Vec<f32>,
    std: Vec<f32>,
    /// Frames per second over skeleton height: turns a step per frame into heights per second.
    scale: f64,
}

impl FootContact {
    /// The term for features in `layout`, normalised by `normalizer`; `None` when the layout
    /// has no contact joint below the joint that carries the root's travel.
    pub fn new(layout: &FeatureLayout, normalizer: &Normalizer) -> Option<FootContact> {
        let skeleton = &layout.skeleton;
        let columns = layout.columns();
        let row_of = |joint: usize, kind: ColumnKind| {
            columns
                .iter()
                .position(|c| c.joint == joint && c.kind == kind)
        };
        let top = layout.root.as_ref().map_or_else(
            || {
                (0..skeleton.len())
                    .find(|&j| skeleton.joints[j].rotates())
                    .unwrap_or(0)
            },
            |r| r.joint,
        );
        let path_to = |joint: usize| -> Option<Vec<usize>> {
            let mut path = vec![joint];
            let mut at = joint;
            while at != top {
                at = skeleton.joints[at].parent?;
                path.push(at);
            }
            path.reverse();
            Some(path)
        };
        let mut joints: Vec<usize> = Vec::new();
        let mut contact_joints = Vec::new();
        for (&contact, label_row) in layout.contact_joints.iter().zip(layout.contact_rows()) {
            let Some(path) = path_to(contact) else {
                continue;
            };
            joints.extend(path);
            contact_joints.push((contact, label_row));
        }
        if contact_joints.is_empty() {
            return None;
        }
        joints.sort_unstable();
        joints.dedup();
        let link_of = |joint: usize| joints.iter().position(|&k| k == joint);
        let mut links = Vec::with_capacity(joints.len());
        let (mut rotating, mut fixed) = (Vec::new(), Vec::new());
        // Depth below the top joint and parent link of every link (parents come first).
        let mut depth = vec![0usize; joints.len()];
        let mut parent = vec![None; joints.len()];
        for (i, &j) in joints.iter().enumerate() {
            let joint = &skeleton.joints[j];
            match row_of(j, ColumnKind::Rotation6d(0)) {
                Some(row) => rotating.push((i, row)),
                None if joint.parent.is_none() && !joint.rotates() => {
                    fixed.push((i, layout.up.canonical_from_file()));
                }
                None => fixed.push((i, IDENTITY)),
            }
            let mut rest = layout.rest_translations[j];
            let mut rows = Vec::new();
            if j == top {
                // The root's place on the ground is constant or travels (added to the
                // velocity); only its height enters the pose.
                rest = [0.0; 3];
                if let Some(row) = row_of(j, ColumnKind::RootHeight) {
                    rows.push((row, UP));
                }
            } else {
                let p = joint
                    .parent
                    .and_then(link_of)
                    .expect("a path's joints chain up");
                parent[i] = Some(p);
                depth[i] = depth[p] + 1;
                for (_, axis) in layout.position_channels.iter().filter(|(p, _)| *p == j) {
                    if let Some(row) = row_of(j, ColumnKind::Position(*axis)) {
                        rows.push((row, axis.index()));
                    }
                }
            }
            links.push(Link {
                translation: (rest, rows),
            });
        }
        let deepest = depth.iter().copied().max().unwrap_or(0);
        let mut levels: Vec<Level> = (0..=deepest)
            .map(|_| Level {
                links: Vec::new(),
                parents: Vec::new(),
                contacts: Vec::new(),
            })
            .collect();
        let mut place = vec![0usize; joints.len()];
        for i in 0..joints.len() {
            let level = &mut levels[depth[i]];
            place[i] = level.links.len();
            level.links.push(i);
            if let Some(p) = parent[i] {
                level.parents.push(place[p]);
            }
        }
        let mut label_rows = Vec::new();
        for (k, (contact, label_row)) in contact_joints.into_iter().enumerate() {
            let i = link_of(contact).expect("on a path");
            let end = skeleton.joints[contact].end_site.unwrap_or([0.0; 3]);
            levels[depth[i]].contacts.push((k, place[i], end));
            label_rows.push(label_row);
        }
        let travel = columns
            .iter()
            .enumerate()
            .filter_map(|(row, c)| match c.kind {
                ColumnKind::RootDisplacement(axis) if c.joint == top => Some((row, axis.index())),
                _ => None,
            })
            .collect();
        Some(FootContact {
            links,
            rotating,
            fixed,
            levels,
            label_rows,
            travel,
            mean: normalizer.mean.clone(),
            std: normalizer.std.clone(),
            scale: layout.fps / layout.skeleton_height.max(f64::MIN_POSITIVE),
        })
    }

    /// The feature rows `rows` of normalised `x` `[B, C, N]` in file units: `[B, rows, N]`.
    fn rows(&self, x: &Tensor<3>, rows: &[usize]) -> Tensor<3> {
        let device = x.device();
        let column = |values: &[f32]| {
            let picked: Vec<f32> = rows.iter().map(|&r| values[r]).collect();
            Tensor::<3>::from_data(TensorData::new(picked, [1, rows.len(), 1]), &device)
        };
        x.clone().select(1, indices(rows, &device)) * column(&self.std) + column(&self.mean)
    }

    /// One feature row of `x` in file units, as `[B * N, 1]` (item-major, as the poses are).
    fn row_per_pose(&self, x: &Tensor<3>, row: usize) -> Tensor<2> {
        let [batch, _, frames] = x.dims();
        self.rows(x, &[row]).reshape([batch * frames, 1])
    }

    /// The speed of every contact point between consecutive frames of the normalised features
    /// `x` `[B, C, N]`, in skeleton heights per second: `[B, N - 1, K]` for K contact joints.
    pub fn contact_speeds(&self, x: &Tensor<3>) -> Tensor<3> {
        let [batch, _, frames] = x.dims();
        let poses = batch * frames;
        let device = x.device();
        let constant = |values: Vec<f32>, shape: [usize; 4]| {
            Tensor::<4>::from_data(TensorData::new(values, shape), &device)
        };
        // Local rotations of every link, `[L, B N, 3, 3]` in link order.
        let mut parts = Vec::new();
        let mut link_order = Vec::new();
        if !self.rotating.is_empty() {
            let rows: Vec<usize> = self
                .rotating
                .iter()
                .flat_map(|&(_, row)| row..row + 6)
                .collect();
            let count = self.rotating.len();
            let six = self
                .rows(x, &rows)
                .reshape([batch, count, 6, frames])
                .permute([1, 0, 3, 2])
                .reshape([count, poses, 6]);
            parts.push(rotation_from_6d(six));
            link_order.extend(self.rotating.iter().map(|&(link, _)| link));
        }
        if !self.fixed.is_empty() {
            let values = self
                .fixed
                .iter()
                .flat_map(|(_, m)| m.iter().flatten().map(|&v| v as f32))
                .collect();
            let count = self.fixed.len();
            parts.push(constant(values, [count, 1, 3, 3]).expand([count, poses, 3, 3]));
            link_order.extend(self.fixed.iter().map(|&(link, _)| link));
        }
        let mut where_is = vec![0usize; self.links.len()];
        for (at, &link) in link_order.iter().enumerate() {
            where_is[link] = at;
        }
        let local = Tensor::cat(parts, 0);
        // Local translations, `[L, B N, 3]` in link order.
        let translation = |link: &Link| -> Tensor<3> {
            let (rest, rows) = &link.translation;
            if rows.is_empty() {
                let values = rest.iter().map(|&v| v as f32).collect();
                return Tensor::<3>::from_data(TensorData::new(values, [1, 1, 3]), &device)
                    .expand([1, poses, 3]);
            }
            let parts = (0..3)
                .map(|axis| match rows.iter().find(|(_, a)| *a == axis) {
                    Some(&(row, _)) => self.row_per_pose(x, row),
                    None => Tensor::<2>::full([poses, 1], rest[axis], &device),
                })
                .collect();
            Tensor::cat(parts, 1).reshape([1, poses, 3])
        };
        let pick = |links: &[usize]| {
            indices(
                &links.iter().map(|&l| where_is[l]).collect::<Vec<_>>(),
                &device,
            )
        };

        let mut points: Vec<Tensor<3>> = Vec::new();
        // The contact index of each point, in the order the levels give them.
        let mut contact_order: Vec<usize> = Vec::new();
        let (mut rotations, mut positions): (Tensor<4>, Tensor<3>) = (
            local.clone().select(0, pick(&self.levels[0].links)),
            translation(&self.links[self.levels[0].links[0]]),
        );
        for (d, level) in self.levels.iter().enumerate() {
            if d > 0 {
                let up = indices(&level.parents, &device);
                let parent_rotation = rotations.select(0, up.clone());
                let links: Vec<&Link> = level.links.iter().map(|&l| &self.links[l]).collect();
                let offsets = if links.iter().all(|l| l.translation.1.is_empty()) {
                    // The usual case: bone offsets only, one constant `[m, 1, 3]` for the level.
                    let values = links
                        .iter()
                        .flat_map(|l| l.translation.0.map(|v| v as f32))
                        .collect();
                    Tensor::<3>::from_data(TensorData::new(values, [links.len(), 1, 3]), &device)
                        .expand([links.len(), poses, 3])
                } else {
                    Tensor::cat(links.iter().map(|l| translation(l)).collect(), 0)
                };
                positions = positions.select(0, up) + turn(parent_rotation.clone(), offsets);
                rotations = compose(parent_rotation, local.clone().select(0, pick(&level.links)));
            }
            if !level.contacts.is_empty() {
                let count = level.contacts.len();
                let at = indices(
                    &level.contacts.iter().map(|c| c.1).collect::<Vec<_>>(),
                    &device,
                );
                let ends = level
                    .contacts
                    .iter()
                    .flat_map(|c| c.2.map(|v| v as f32))
                    .collect();
                let ends = Tensor::<3>::from_data(TensorData::new(ends, [count, 1, 3]), &device)
                    .expand([count, poses, 3]);
                points.push(
                    positions.clone().select(0, at.clone())
                        + turn(rotations.clone().select(0, at), ends),
                );
                contact_order.extend(level.contacts.iter().map(|c| c.0));
            }
        }
        let contacts = contact_order.len();
        // Back in the layout's contact order.
        let mut back = vec![0usize; contacts];
        for (at, &k) in contact_order.iter().enumerate() {
            back[k] = at;
        }
        let points = Tensor::cat(points, 0)
            .select(0, indices(&back, &device))
            .reshape([contacts, batch, frames, 3]);
        let mut step = points.clone().narrow(2, 1, frames - 1) - points.narrow(2, 0, frames - 1);
        if !self.travel.is_empty() {
            let parts = (0..3)
                .map(|axis| match self.travel.iter().find(|(_, a)| *a == axis) {
                    Some(&(row, _)) => self.rows(x, &[row]),
                    None => Tensor::<3>::zeros([batch, 1, frames], &device),
                })
                .collect();
            // `[1, B, N - 1, 3]`: the displacement into each frame from the one before.
            let travel = Tensor::cat(parts, 1)
                .narrow(2, 1, frames - 1)
                .swap_dims(1, 2)
                .reshape([1, batch, frames - 1, 3]);
            step = step + travel;
        }
        step.square()
            .sum_dim(3)
            .sqrt()
            .reshape([contacts, batch, frames - 1])
            .permute([1, 2, 0])
            .mul_scalar(self.scale)
    }

    /// The term for the prediction `x0_hat` of the clean batch `x0` (both normalised,
    /// `[B, C, N]`): the mean over frame pairs and contact joints of the squared speed of each
    /// predicted contact point, weighted by the clip's contact label at both frames of the pair.
    pub fn loss(&self, x0_hat: &Tensor<3>, x0: &Tensor<3>) -> Tensor<1> {
        let frames = x0.dims()[2];
        // `[B, N, K]`
        let labels = self
            .rows(x0, &self.label_rows)
            .clamp(0.0, 1.0)
            .swap_dims(1, 2);
        let both = labels
            .clone()
            .narrow(1, 1, frames - 1)
            .min_pair(labels.narrow(1, 0, frames - 1));
        let speeds = self.contact_speeds(x0_hat);
        (speeds.square() * both).mean()
    }
}

/// A tensor of indices.
fn indices(values: &[usize], device: &Device) -> Tensor<1, Int> {
    let values: Vec<i64> = values.iter().map(|&v| v as i64).collect();
    let count = values.len();
    Tensor::<1, Int>::from_data(TensorData::new(values, [count]), device)
}

/// The rotation matrices `[L, P, 3, 3]` (rows) of 6D rotations `[L, P, 6]`, by Gram-Schmidt
/// as the runtime decodes them.
fn rotation_from_6d(six: Tensor<3>) -> Tensor<4> {
    let unit = |v: Tensor<3>| {
        let norm = v.clone().square().sum_dim(2).sqrt().clamp_min(1e-8);
        v / norm
    };
    let a = unit(six.clone().narrow(2, 0, 3));
    let c = unit(cross(&a, &six.narrow(2, 3, 3)));
    let b = cross(&c, &a);
    Tensor::stack(vec![a, b, c], 2)
}

/// Rotations `[L, P, 3, 3]` applied to vectors `[L, P, 3]` (or `[1, 1, 3]`, one for all), as a
/// broadcast product and a sum: burn's matrix product would run `L P` tiny products one by one.
fn turn(rotation: Tensor<4>, v: Tensor<3>) -> Tensor<3> {
    let [links, poses, _, _] = rotation.dims();
    let [a, b, _] = v.dims();
    (rotation * v.reshape([a, b, 1, 3]))
        .sum_dim(3)
        .reshape([links, poses, 3])
}

/// The products `a b` of rotations `[L, P, 3, 3]`, by broadcasting as in [`turn`].
fn compose(a: Tensor<4>, b: Tensor<4>) -> Tensor<4> {
    let [links, poses, _, _] = a.dims();
    let a: Tensor<5> = a.reshape([links, poses, 3, 3, 1]);
    let b: Tensor<5> = b.reshape([links, poses, 1, 3, 3]);
    (a * b).sum_dim(3).reshape([links, poses, 3, 3])
}

/// The cross product of two `[L, P, 3]` vector fields.
fn cross(u: &Tensor<3>, v: &Tensor<3>) -> Tensor<3> {
    let part = |t: &Tensor<3>, i: usize| t.clone().narrow(2, i, 1);
    Tensor::cat(
        vec![
            part(u, 1) * part(v, 2) - part(u, 2) * part(v, 1),
            part(u, 2) * part(v, 0) - part(u, 0) * part(v, 2),
            part(u, 0) * part(v, 1) - part(u, 1) * part(v, 0),
        ],
        2,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clip_data::ClipData;
    use crate::config::TrainConfig;
    use burn::tensor::Device;
    use sinmdm::motion::{decode, global_poses};
    use std::path::Path;

    fn clip(name: &str) -> ClipData {
        let config = TrainConfig::parse(include_str!("../../configs/default.yaml")).unwrap();
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/data/bvh")
            .join(name);
        ClipData::load(&path, &config.data, &config.model).unwrap()
    }

    /// Contact speeds by the runtime's own decoding and forward kinematics, in heights per
    /// second: `[frame pair][contact]`.
    fn runtime_speeds(data: &ClipData) -> Vec<Vec<f64>> {
        let layout = &data.facts.layout;
        let features = data.facts.normalizer.denormalize(data.features.view());
        let poses = global_poses(&decode(layout, features.view()).unwrap());
        poses
            .windows(2)
            .map(|pair| {
                layout
                    .contact_joints
                    .iter()
                    .map(|&j| {
                        let (a, b) = (pair[0].contact_point(j), pair[1].contact_point(j));
                        let d: f64 = (0..3).map(|i| (b[i] - a[i]).powi(2)).sum();
                        d.sqrt() * layout.fps / layout.skeleton_height
                    })
                    .collect()
            })
            .collect()
    }

    fn as_batch(data: &ClipData) -> Tensor<3> {
        let (rows, frames) = data.features.dim();
        let values: Vec<f32> = data.features.iter().copied().collect();
        Tensor::<3>::from_data(TensorData::new(values, [1, rows, frames]), &Device::flex())
    }

    #[test]
    fn contact_speeds_match_the_runtime_forward_kinematics() {
        // A human (two-bone legs, End Sites beyond the toes), a fox (longer legs) and a dance
        // clip with a different rig: the tensor kinematics against the runtime's decoding.
        for name in [
            "human_walk_cmu_131_01.bvh",
            "fox_survey_khronos.bvh",
            "human_dance_rokoko_jesse.bvh",
        ] {
            let data = clip(name);
            let term = FootContact::new(&data.facts.layout, &data.facts.normalizer).unwrap();
            let speeds = term.contact_speeds(&as_batch(&data));
            let [_, pairs, contacts] = speeds.dims();
            let got = speeds.into_data().try_into_vec::<f32>().unwrap();
            let expected = runtime_speeds(&data);
            assert_eq!(pairs, expected.len(), "{name}");
            assert_eq!(contacts, data.facts.layout.contact_joints.len(), "{name}");
            let mut worst = 0.0f64;
            for (f, row) in expected.iter().enumerate() {
                for (k, &e) in row.iter().enumerate() {
                    let g = f64::from(got[f * contacts + k]);
                    worst = worst.max((g - e).abs() / (1.0 + e));
                }
            }
            assert!(worst < 1e-3, "{name}: worst relative difference {worst}");
        }
    }

    #[test]
    fn the_loss_weighs_speeds_by_labels_at_both_frames() {
        let data = clip("human_walk_cmu_131_01.bvh");
        let layout = &data.facts.layout;
        let term = FootContact::new(layout, &data.facts.normalizer).unwrap();
        let x = as_batch(&data);
        let loss = f64::from(term.loss(&x, &x).into_scalar::<f32>());
        let speeds = runtime_speeds(&data);
        let features = data.facts.normalizer.denormalize(data.features.view());
        let rows = layout.contact_rows();
        let label = |f: usize, k: usize| f64::from(features[[rows[k], f]]).clamp(0.0, 1.0);
        let mut sum = 0.0;
        for (f, row) in speeds.iter().enumerate() {
            for (k, s) in row.iter().enumerate() {
                sum += label(f, k).min(label(f + 1, k)) * s * s;
            }
        }
        let expected = sum / (speeds.len() * rows.len()) as f64;
        assert!(expected > 0.0);
        assert!(
            (loss - expected).abs() < 1e-3 * expected,
            "{loss} against {expected}"
        );
        // With no foot on the ground there is nothing to hold.
        let mut swinging = data.clone();
        for &r in &rows {
            let m = data.facts.normalizer.mean[r];
            let s = data.facts.normalizer.std[r];
            swinging.features.row_mut(r).fill(-m / s);
        }
        let none = term.loss(&x, &as_batch(&swinging)).into_scalar::<f32>();
        assert_eq!(none, 0.0);
    }
}
