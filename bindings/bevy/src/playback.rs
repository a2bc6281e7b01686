//! What a character shows and how it gets it: the frames made and not yet passed, the pose
//! between two of them, and the request on the compute pool that makes more.

use std::collections::VecDeque;

use bevy_tasks::{Task, block_on, futures::check_ready};
use sinmdm::Pose;

use crate::frame::interpolate;

/// The model frame on show at `clock` (in model frames; 0 before the first) and the fraction of
/// the way to the next.
pub(crate) fn on_show(clock: Option<f64>) -> (usize, f32) {
    let clock = clock.unwrap_or(0.0);
    let base = clock.floor() as usize;
    (base, (clock - base as f64) as f32)
}

/// The frames that must be made to show frame `base` plus `frac`: up to it, and the next one
/// too when interpolating between them.
pub(crate) fn needed(base: usize, frac: f32, interpolated: bool) -> usize {
    base + if interpolated && frac > 0.0 { 2 } else { 1 }
}

/// A character's frames, from model frame `first` on: those ready and the one on show.
#[derive(Default)]
pub(crate) struct Frames {
    frames: VecDeque<Pose>,
    first: usize,
}

impl Frames {
    /// The model frame after the last one ready.
    pub(crate) fn end(&self) -> usize {
        self.first + self.frames.len()
    }

    /// Frames ready past model frame `base`.
    pub(crate) fn ready_past(&self, base: usize) -> usize {
        self.end().saturating_sub(base + 1)
    }

    /// Appends newly made frames.
    pub(crate) fn extend(&mut self, poses: impl IntoIterator<Item = Pose>) {
        self.frames.extend(poses);
    }

    /// The pose at model frame `base` plus `frac` (the last frame ready when the motion stopped
    /// short of it), forgetting the frames before `base`, which are not needed again.
    pub(crate) fn show(&mut self, base: usize, frac: f32, interpolated: bool) -> Option<Pose> {
        let drop = base
            .saturating_sub(self.first)
            .min(self.frames.len().saturating_sub(1));
        self.frames.drain(..drop);
        self.first += drop;
        let i = base.checked_sub(self.first)?;
        let a = self.frames.get(i).or_else(|| self.frames.back())?;
        match self.frames.get(i + 1) {
            Some(b) if interpolated && frac > 0.0 => Some(interpolate(a, b, frac)),
            _ => Some(a.clone()),
        }
    }
}

/// What a request gives back: the engine, what it made (or why not) and the seconds it took.
pub(crate) type Made<E, R> = (Box<E>, R, f64);

/// What a motion maker (an engine moved to the compute pool for each request) is doing.
pub(crate) enum Maker<E, R> {
    /// Waiting for the next request.
    Idle(Box<E>),
    /// A request on the compute pool.
    Busy(Task<Made<E, R>>),
    /// Stopped by an error (kept by its owner).
    Stopped,
}

impl<E, R> Maker<E, R> {
    /// The request's result once it has finished (waiting for it when `wait`), leaving the
    /// maker stopped until its owner says what comes next; `None` while none has finished.
    pub(crate) fn finished(&mut self, wait: bool) -> Option<Made<E, R>> {
        let Maker::Busy(task) = self else {
            return None;
        };
        let done = if wait {
            Some(block_on(task))
        } else {
            check_ready(task)
        };
        if done.is_some() {
            *self = Maker::Stopped;
        }
        done
    }

    /// The idle engine, taken for a request (the maker is stopped until the request is given
    /// back as busy); `None` while busy or stopped.
    pub(crate) fn take_idle(&mut self) -> Option<Box<E>> {
        match std::mem::replace(self, Maker::Stopped) {
            Maker::Idle(engine) => Some(engine),
            other => {
                *self = other;
                None
            }
        }
    }
}
