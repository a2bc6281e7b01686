//! Joints of the model's skeleton by name, and body parts (a joint and everything below it).

use super::TaskError;
use crate::motion::FeatureLayout;

/// Joint indices for names, in the model's skeleton.
pub fn joints_by_name(layout: &FeatureLayout, names: &[String]) -> Result<Vec<usize>, TaskError> {
    names
        .iter()
        .map(|name| {
            layout
                .skeleton
                .find(name)
                .ok_or_else(|| TaskError::UnknownJoint {
                    name: name.clone(),
                    available: layout
                        .skeleton
                        .joints
                        .iter()
                        .map(|j| j.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                })
        })
        .collect()
}

/// `joint` and every joint below it (nothing for an index past the skeleton).
pub fn subtree(layout: &FeatureLayout, joint: usize) -> Vec<usize> {
    let joints = &layout.skeleton.joints;
    if joint >= joints.len() {
        return Vec::new();
    }
    let mut inside = vec![false; joints.len()];
    inside[joint] = true;
    // Parents precede children, so one pass in order marks every descendant.
    for j in joint + 1..joints.len() {
        if let Some(p) = joints[j].parent {
            inside[j] = inside[p];
        }
    }
    (0..joints.len()).filter(|&j| inside[j]).collect()
}
