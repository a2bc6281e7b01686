//! Poses a game supplies to a stream, frame by frame, for composition: kept until the blocks
//! that cover them have been made, then dropped, so memory stays flat.

use std::collections::VecDeque;

use ndarray::{Array2, s};

use crate::model_file::ModelMetadata;
use crate::motion::{MotionError, Pose, features_from_poses, motion_from_poses};

/// Supplied poses by stream frame. Pose `i` supplied in all belongs to stream frame `i`, always:
/// poses for frames already past every block that could use them are dropped on arrival, never
/// moved to later frames.
#[derive(Debug, Clone, Default)]
pub struct Guide {
    /// The stream frame of `poses[0]`.
    first: usize,
    poses: VecDeque<Pose>,
    /// Frames before this one are no longer needed by any block.
    floor: usize,
}

impl Guide {
    /// The stream frame the next supplied pose belongs to.
    pub fn next_frame(&self) -> usize {
        self.first + self.poses.len()
    }

    /// Appends poses for the frames after the last supplied one, checked against the skeleton.
    pub fn supply(&mut self, metadata: &ModelMetadata, poses: &[Pose]) -> Result<(), MotionError> {
        let layout = &metadata.layout;
        motion_from_poses(&layout.skeleton, layout.fps, poses)?;
        self.poses.extend(poses.iter().cloned());
        self.drop_below_floor();
        Ok(())
    }

    /// Forgets poses before stream frame `frame`.
    pub fn forget_before(&mut self, frame: usize) {
        self.floor = self.floor.max(frame);
        self.drop_below_floor();
    }

    fn drop_below_floor(&mut self) {
        while self.first < self.floor && !self.poses.is_empty() {
            self.poses.pop_front();
            self.first += 1;
        }
    }

    /// Normalised features `[F, frames]` of the supplied poses for stream frames
    /// `start..start + frames`, and per frame whether a pose was supplied for it (frames without
    /// one hold zeros). The frame before `start`, when supplied, gives the first root
    /// displacement.
    pub fn features(
        &self,
        metadata: &ModelMetadata,
        start: usize,
        frames: usize,
    ) -> Result<(Array2<f32>, Vec<bool>), MotionError> {
        let f = metadata.network.features;
        let mut out = Array2::<f32>::zeros((f, frames));
        let mut covered = vec![false; frames];
        let from = start.saturating_sub(1).max(self.first);
        let to = (start + frames).min(self.next_frame());
        if to <= start.max(from) {
            return Ok((out, covered));
        }
        let poses: Vec<Pose> = (from..to)
            .map(|frame| self.poses[frame - self.first].clone())
            .collect();
        let raw = features_from_poses(&metadata.layout, &poses)?;
        let normalized = metadata.normalizer.normalize(raw.view());
        let skip = start - from.min(start);
        let first = from.max(start);
        out.slice_mut(s![.., first - start..to - start])
            .assign(&normalized.slice(s![.., skip..]));
        for slot in &mut covered[first - start..to - start] {
            *slot = true;
        }
        Ok((out, covered))
    }
}
