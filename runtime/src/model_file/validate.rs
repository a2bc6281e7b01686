//! Every rule a model file's metadata must follow before the runtime uses it: each field
//! against its bounds and against the others. A file from a modder, a pipeline or a download
//! can hold anything; after these checks no index is out of range, no number is non-finite
//! where it is used, and no size makes an allocation the runtime would not make for a real model.

use std::collections::HashSet;

use super::{ModelMetadata, PREDICTION, SCHEDULE};
use crate::limits::{
    MAX_DIFFUSION_STEPS, MAX_FEATURES, MAX_FPS, MAX_JOINTS, MAX_NAME_BYTES, MAX_NETWORK_CHANNELS,
    MAX_SAMPLE_FRAMES, MAX_WINDOW,
};
use crate::motion::features::{FeatureLayout, RootFeatures};
use crate::motion::math::{self, Mat3};
use crate::motion::skeleton::{Channel, Skeleton};

/// Every problem of `m`, each naming the field and the value; empty when the metadata is sound.
pub fn problems(m: &ModelMetadata) -> Vec<String> {
    let mut p = Problems::default();
    skeleton(&mut p, &m.layout.skeleton);
    if p.0.is_empty() {
        // The layout's indices are checked only against a sound skeleton.
        layout(&mut p, m);
    }
    network_and_normalizer(&mut p, m);
    let d = &m.diffusion;
    if !(2..=MAX_DIFFUSION_STEPS).contains(&d.steps) {
        p.add(format!(
            "diffusion.steps is {}; it must be between 2 and {MAX_DIFFUSION_STEPS}",
            d.steps
        ));
    }
    if d.schedule != SCHEDULE || d.prediction != PREDICTION {
        p.add(format!(
            "diffusion.schedule '{}' / prediction '{}': this runtime runs '{SCHEDULE}' / '{PREDICTION}'",
            d.schedule, d.prediction
        ));
    }
    if m.training.clip_frames > MAX_SAMPLE_FRAMES {
        p.add(format!(
            "training.clip_frames is {}; the most a model can make is {} frames",
            m.training.clip_frames, MAX_SAMPLE_FRAMES
        ));
    }
    p.0
}

#[derive(Default)]
struct Problems(Vec<String>);

impl Problems {
    fn add(&mut self, message: String) {
        self.0.push(message);
    }

    fn finite(&mut self, field: &str, values: &[f64]) {
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            self.add(format!("{field} holds {v}; it must be a finite number"));
        }
    }

    fn positive(&mut self, field: &str, value: f64, most: f64) {
        if !(value.is_finite() && value > 0.0 && value <= most) {
            self.add(format!(
                "{field} is {value}; it must be a positive number up to {most}"
            ));
        }
    }
}

fn skeleton(p: &mut Problems, s: &Skeleton) {
    let joints = &s.joints;
    if joints.is_empty() || joints.len() > MAX_JOINTS {
        p.add(format!(
            "layout.skeleton.joints has {} joints; it must have 1 to {MAX_JOINTS}",
            joints.len()
        ));
        return;
    }
    let mut names = HashSet::new();
    for (i, joint) in joints.iter().enumerate() {
        let field = format!("layout.skeleton.joints[{i}]");
        if joint.name.trim().is_empty() || joint.name.len() > MAX_NAME_BYTES {
            p.add(format!(
                "{field}.name is '{}'; a name has 1 to {MAX_NAME_BYTES} bytes",
                joint.name.escape_debug()
            ));
        } else if !names.insert(joint.name.as_str()) {
            p.add(format!("{field}.name '{}' is used twice", joint.name));
        }
        match (i, joint.parent) {
            (0, Some(parent)) => p.add(format!(
                "{field}.parent is {parent}; the first joint is the root and has none"
            )),
            (_, None) if i > 0 => p.add(format!(
                "{field}.parent is missing; only the first joint is a root"
            )),
            (_, Some(parent)) if parent >= i => p.add(format!(
                "{field}.parent is {parent}; a parent must come before its child (index below {i})"
            )),
            _ => {}
        }
        p.finite(&format!("{field}.offset"), &joint.offset.0);
        if let Some(end) = joint.end_site {
            p.finite(&format!("{field}.end_site"), &end.0);
        }
        let rotations = joint.rotation_order();
        let positions = joint.position_axes();
        let distinct =
            |axes: &[crate::motion::Axis]| axes.iter().collect::<HashSet<_>>().len() == axes.len();
        // One to three rotation axes, as the BVH reader takes them (a hinge with one axis is
        // common); its rotation is learnt in 6D and decoded onto its axes.
        if rotations.len() > 3 || !distinct(&rotations) {
            p.add(format!(
                "{field}.channels has rotations {rotations:?}; a joint has up to three distinct axes"
            ));
        }
        if !distinct(&positions) {
            p.add(format!(
                "{field}.channels repeats a position axis: {positions:?}"
            ));
        }
    }
}

fn layout(p: &mut Problems, m: &ModelMetadata) {
    let l = &m.layout;
    let joints = &l.skeleton.joints;
    let n = joints.len();
    p.positive("layout.fps", l.fps, MAX_FPS);
    p.positive("layout.skeleton_height", l.skeleton_height, f64::MAX);
    p.positive(
        "layout.contact_speed_threshold",
        l.contact_speed_threshold,
        f64::MAX,
    );
    if let Some(ground) = l.ground {
        p.finite("layout.ground", &[ground]);
    }
    if l.rest_translations.len() != n {
        p.add(format!(
            "layout.rest_translations has {} entries for {n} joints",
            l.rest_translations.len()
        ));
    }
    for (i, t) in l.rest_translations.iter().enumerate() {
        p.finite(&format!("layout.rest_translations[{i}]"), &t.0);
    }
    if let Some(root) = &l.root {
        root_layout(p, l, root);
    }
    let mut seen = HashSet::new();
    for (i, &j) in l.rotation_joints.iter().enumerate() {
        let field = format!("layout.rotation_joints[{i}]");
        if j >= n {
            p.add(format!("{field} is {j}; the skeleton has {n} joints"));
        } else if joints[j].rotation_order().is_empty() {
            p.add(format!(
                "{field} is joint '{}', which has no rotation channels",
                joints[j].name
            ));
        } else if !seen.insert(j) {
            p.add(format!("{field}: joint {j} is listed twice"));
        }
    }
    let mut seen = HashSet::new();
    for (i, &(j, axis)) in l.position_channels.iter().enumerate() {
        let field = format!("layout.position_channels[{i}]");
        if j >= n {
            p.add(format!("{field} is joint {j}; the skeleton has {n} joints"));
        } else if !joints[j].channels.contains(&Channel::Position(axis)) {
            p.add(format!(
                "{field} is {axis:?} of joint '{}', which has no such channel",
                joints[j].name
            ));
        } else if !seen.insert((j, axis)) {
            p.add(format!("{field}: listed twice"));
        }
    }
    let mut seen = HashSet::new();
    for (i, &j) in l.contact_joints.iter().enumerate() {
        let field = format!("layout.contact_joints[{i}]");
        if j >= n {
            p.add(format!("{field} is {j}; the skeleton has {n} joints"));
        } else if !seen.insert(j) {
            p.add(format!("{field}: joint {j} is listed twice"));
        }
    }
}

/// The root's fields: its joint, axes, start, frame and a heading-relative root's facts.
fn root_layout(p: &mut Problems, l: &FeatureLayout, root: &RootFeatures) {
    let n = l.skeleton.joints.len();
    if root.joint >= n {
        p.add(format!(
            "layout.root.joint is {}; the skeleton has {n} joints",
            root.joint
        ));
    }
    let axes: HashSet<_> = root.axes.iter().collect();
    if root.axes.is_empty() || axes.len() != root.axes.len() {
        p.add(format!(
            "layout.root.axes is {:?}; it must list 1 to 3 distinct axes",
            root.axes
        ));
    }
    p.finite("layout.root.start_position", &root.start_position.0);
    if let Some(h) = &root.heading {
        for (field, j) in [("left", h.left), ("right", h.right)] {
            if j >= n {
                p.add(format!(
                    "layout.root.heading.{field} is {j}; the skeleton has {n} joints"
                ));
            }
        }
        if h.left == h.right {
            p.add(format!(
                "layout.root.heading.left and .right are both {}; they must differ",
                h.left
            ));
        }
        if !(h.smoothing.is_finite() && (0.0..=10.0).contains(&h.smoothing)) {
            p.add(format!(
                "layout.root.heading.smoothing is {}; it must be 0 to 10 seconds",
                h.smoothing
            ));
        }
        p.finite("layout.root.heading.start", &[h.start]);
        if root.axes.len() != 3 {
            p.add(format!(
                "layout.root.axes is {:?}; a heading-relative root moves on all three",
                root.axes
            ));
        }
        if root.joint < n && !l.rotation_joints.contains(&root.joint) {
            p.add(format!(
                "layout.root.joint {} has no rotation column; a heading-relative root turns",
                root.joint
            ));
        }
    }
    if !is_rotation(&root.frame) {
        p.add(format!(
            "layout.root.frame is {:?}; it must be a rotation matrix",
            root.frame
        ));
    }
}

fn network_and_normalizer(p: &mut Problems, m: &ModelMetadata) {
    let net = &m.network;
    let width = m.layout.width();
    if net.features == 0 || net.features > MAX_FEATURES {
        p.add(format!(
            "network.features is {}; it must be between 1 and {MAX_FEATURES}",
            net.features
        ));
    } else if net.features != width {
        p.add(format!(
            "network.features is {} but the feature layout has {width} columns",
            net.features
        ));
    }
    if net.channels > MAX_NETWORK_CHANNELS || net.window > MAX_WINDOW {
        p.add(format!(
            "network.channels {} / window {}: the most are {MAX_NETWORK_CHANNELS} / {MAX_WINDOW}",
            net.channels, net.window
        ));
    }
    if let Err(e) = net.shape().check() {
        p.add(format!("network: {e}"));
    } else if net.receptive_field != net.shape().receptive_field() {
        p.add(format!(
            "network.receptive_field is {} but a window of {} makes it {}",
            net.receptive_field,
            net.window,
            net.shape().receptive_field()
        ));
    }
    let norm = &m.normalizer;
    if norm.mean.len() != net.features || norm.std.len() != net.features {
        p.add(format!(
            "normalizer has {} means and {} stds for {} features",
            norm.mean.len(),
            norm.std.len(),
            net.features
        ));
    }
    if let Some(i) = norm.mean.iter().position(|v| !v.is_finite()) {
        p.add(format!(
            "normalizer.mean[{i}] is {}; it must be finite",
            norm.mean[i]
        ));
    }
    if let Some(i) = norm.std.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
        p.add(format!(
            "normalizer.std[{i}] is {}; it must be a positive number",
            norm.std[i]
        ));
    }
}

/// Whether `m` is a rotation: finite, orthonormal and right-handed, to 1e-6.
fn is_rotation(m: &Mat3) -> bool {
    let product = m * m.transpose();
    m.is_finite()
        && math::mat_max_abs_diff(&product, &math::IDENTITY) < 1e-6
        && (m.determinant() - 1.0).abs() < 1e-6
}
