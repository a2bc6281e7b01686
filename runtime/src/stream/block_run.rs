//! A stream's blocks one at a time: starting a block's sampling run (its window, the frames
//! carried in, supplied poses, steering and noise), and turning a finished run into final frames.

use ndarray::{Array2, Axis, s};

use super::{Frame, Stream, block_seed};
use crate::diffusion::sampler::{Guidance, Inpainting, Sampler};
use crate::motion::features::heading::yaw;
use crate::motion::feet::{Anchor, Feet, Kept, PlantOptions, plant_feet};
use crate::motion::math::Vec3;
use crate::motion::up::UP;
use crate::motion::{LocalMotion, RootStart, decode, decode_from, root_track};
use crate::steer::plan_steering;
use crate::stream::blocks;
use crate::tasks::TaskError;
use crate::tasks::mask::soft_mask;

/// A block whose sampling run is under way (see [`Stream::prepare`]).
#[derive(Debug)]
pub(super) struct PendingBlock {
    window: blocks::Window,
    pub(super) sampler: Sampler,
    /// Per window frame, whether steering commands the root's travel there (planting leaves
    /// those roots where the steering put them).
    travel_commanded: Vec<bool>,
}

impl Stream {
    /// Starts the next block's sampling run: its window, guidance and noise.
    pub(super) fn start_block(&mut self) -> Result<PendingBlock, TaskError> {
        let sizes = self.sizes;
        let window = sizes.window(self.blocks);
        let f = self.metadata.network.features;
        let n = window.frames;
        let mut reference = Array2::<f32>::zeros((f, n));
        let mut mask = Array2::<f32>::zeros((f, n));
        if let Some(carried) = &self.carried {
            reference
                .slice_mut(s![.., ..window.carried])
                .assign(carried);
            for (i, w) in sizes.carry_weights(&window).into_iter().enumerate() {
                mask.column_mut(i).fill(w);
            }
        }
        if !self.compose_rows.is_empty() {
            let (guide, covered) = self.guide.features(&self.metadata, window.start, n)?;
            let weights = soft_mask(&covered, sizes.ramp);
            for &row in &self.compose_rows {
                for i in window.context..n {
                    if weights[i] > mask[[row, i]] {
                        mask[[row, i]] = weights[i];
                        reference[[row, i]] = guide[[row, i]];
                    }
                }
            }
        }
        let steering = if self.commands.is_empty() {
            None
        } else {
            let course = match (self.last_course, window.context) {
                (Some(last), c) if c > 0 => Some((c - 1, last)),
                _ => RootStart::of(&self.metadata.layout).map(|start| (0, start)),
            };
            match course {
                Some((anchor, course)) => {
                    let commands = self.commands_for(window.start, n);
                    let planned =
                        plan_steering(&self.metadata, &commands, anchor, course, sizes.ramp)
                            .map_err(TaskError::Steer)?;
                    for line in planned.warnings {
                        if !self.warnings.contains(&line) {
                            self.warnings.push(line);
                        }
                    }
                    planned.steering
                }
                None => None,
            }
        };
        // Commands the next blocks cannot reach are dropped.
        let floor = (window.start + window.frames).saturating_sub(sizes.context + sizes.ramp + 1);
        while self.commands_first < floor && !self.commands.is_empty() {
            self.commands.pop_front();
            self.commands_first += 1;
        }
        // Supplied poses the next blocks cannot reach are dropped (also when nothing is composed,
        // so supplying poses never makes memory grow).
        self.guide.forget_before(
            (window.start + window.frames).saturating_sub(sizes.context + sizes.ramp + 1),
        );
        let inpainting = mask
            .iter()
            .any(|&m| m > 0.0)
            .then_some(Inpainting { reference, mask });
        let guidance = Guidance {
            inpainting,
            harmonization: None,
            steering,
        };
        let travel_commanded = guidance
            .steering
            .as_ref()
            .map(|s| s.travel_commanded())
            .unwrap_or_default();
        let seed = block_seed(self.seed, self.blocks as u64);
        let sampler = if self.noise_on_this_thread {
            Sampler::new_on_this_thread(&self.schedule, &guidance, 1, f, n, seed)?
        } else {
            Sampler::new(&self.schedule, &guidance, 1, f, n, seed)?
        };
        let sampler = sampler.with_method(self.method)?;
        Ok(PendingBlock {
            window,
            sampler,
            travel_commanded,
        })
    }

    /// Decodes a finished block and queues its final frames.
    pub(super) fn complete_block(&mut self, pending: PendingBlock) -> Result<(), TaskError> {
        let PendingBlock {
            window,
            sampler,
            travel_commanded,
        } = pending;
        let sizes = self.sizes;
        let n = window.frames;
        let normalized = sampler.into_sample().index_axis_move(Axis(0), 0);
        let keep = sizes.context + sizes.ramp;
        // Nothing of the stream changes until every fallible step has passed: a block that
        // cannot be decoded leaves the stream as it was (the same block is made again).
        let carried = normalized.slice(s![.., n - keep..]).to_owned();
        let raw = self.metadata.normalizer.denormalize(normalized.view());

        // Decode the context and the final frames; carry the root on from the last chunk.
        let done = window.finalised(&sizes);
        let layout = &self.metadata.layout;
        let joints = layout.skeleton.len();
        let rows = raw.slice(s![.., ..done.end]);
        let (motion, last_root, last_course) = self.carry_root_on(layout, rows, &done)?;
        let motion = if self.feet == Feet::Planted {
            self.plant(layout, motion, raw.view(), &done, &travel_commanded)?
        } else {
            motion
        };
        self.carried = Some(carried);
        self.last_root = last_root;
        self.last_course = last_course;
        for frame in done.clone() {
            let range = frame * joints..(frame + 1) * joints;
            self.ready.push_back(Frame {
                features: raw.column(frame).to_vec(),
                rotations: motion.rotations[range.clone()].to_vec(),
                translations: motion.translations[range].to_vec(),
            });
        }
        let tail_from = (done.end - sizes.context) * joints;
        self.tail = Some(LocalMotion {
            skeleton: layout.skeleton.clone(),
            fps: layout.fps,
            rotations: motion.rotations[tail_from..].to_vec(),
            translations: motion.translations[tail_from..].to_vec(),
        });
        self.blocks += 1;
        Ok(())
    }

    /// Decodes the finalised rows with the root carried on from the last chunk: a
    /// heading-relative root's course turned and moved to go on from the last final frame's
    /// position and facing, a world root shifted to it. Gives the motion and the new last root
    /// and course (the stream itself is not changed).
    fn carry_root_on(
        &self,
        layout: &crate::motion::FeatureLayout,
        rows: ndarray::ArrayView2<'_, f32>,
        done: &std::ops::Range<usize>,
    ) -> Result<(LocalMotion, Option<Vec3>, Option<RootStart>), TaskError> {
        let joints = layout.skeleton.len();
        let mut last_root = self.last_root;
        let mut last_course = self.last_course;
        let mut motion = match RootStart::of(layout) {
            // A heading-relative root: the block's course is turned and moved so that it goes
            // on from the last final frame's position and facing.
            Some(first) => {
                let start = match (self.last_course, done.start > 0) {
                    (Some(last), true) => {
                        let from_layout = root_track(layout, rows, None);
                        let (positions, headings) = from_layout.unwrap_or_default();
                        let k = done.start - 1;
                        let turn = last.heading - headings[k];
                        let mut travelled = positions[k] - first.position;
                        travelled[UP] = 0.0;
                        RootStart {
                            position: last.position - yaw(turn) * travelled,
                            heading: first.heading + turn,
                        }
                    }
                    _ => first,
                };
                let (positions, headings) =
                    root_track(layout, rows, Some(start)).unwrap_or_default();
                last_course = Some(RootStart {
                    position: positions[done.end - 1],
                    heading: headings[done.end - 1],
                });
                decode_from(layout, rows, Some(start))?
            }
            None => decode(layout, rows)?,
        };
        if let Some(root) = layout.root.as_ref().filter(|r| r.heading.is_none()) {
            let r = root.joint;
            if let (Some(last), true) = (self.last_root, done.start > 0) {
                let offset = last - motion.translations[(done.start - 1) * joints + r];
                for frame in 0..done.end {
                    let t = &mut motion.translations[frame * joints + r];
                    *t += offset;
                }
            }
            last_root = Some(motion.translations[(done.end - 1) * joints + r]);
        }
        Ok((motion, last_root, last_course))
    }

    /// Plants the feet of the decoded frames, keeping the frames handed out as they were and
    /// the roots steering commanded where it put them.
    fn plant(
        &self,
        layout: &crate::motion::FeatureLayout,
        mut motion: LocalMotion,
        raw: ndarray::ArrayView2<'_, f32>,
        done: &std::ops::Range<usize>,
        travel_commanded: &[bool],
    ) -> Result<LocalMotion, TaskError> {
        let joints = layout.skeleton.len();
        if let Some(tail) = &self.tail {
            // What was handed out stays as it was.
            let kept = done.start * joints;
            motion.rotations[..kept].copy_from_slice(&tail.rotations);
            motion.translations[..kept].copy_from_slice(&tail.translations);
        }
        let labels = layout.contact_labels(raw.slice(s![.., ..done.end]));
        let kept = Kept {
            joints: (0..done.end)
                .map(|frame| vec![frame < done.start; joints])
                .collect(),
            root: (0..done.end)
                .map(|frame| {
                    frame < done.start || travel_commanded.get(frame).copied() == Some(true)
                })
                .collect(),
        };
        let options = PlantOptions {
            anchor: Anchor::Landing,
            ..PlantOptions::default()
        };
        Ok(plant_feet(layout, &motion, &labels, &kept, &options)?.0)
    }
}
