//! Where each block of a stream sits: its window of frames, which of them are the previous
//! block's context, which it finalises and which it holds back for the next block to settle.
//!
//! With `C` context frames, `R` ramp frames and blocks of `B` frames, block 0's window is the
//! `B + R` frames `0..B+R`; it finalises `0..B` and holds back `B..B+R`. Block `k >= 1` starts
//! at `made - C`, where `made = k B` frames are final: its window is `C` final frames kept
//! exactly, the `R` held-back frames kept with weights easing from 1 down to `1/R`, and `B`
//! new frames; it finalises the `B` frames from `made` on (the held-back ones, now settled
//! against what follows, and the first `B - R` new ones) and holds back its last `R`.

use crate::diffusion::noise::word;
use crate::tasks::mask::soft_mask;

/// The noise stream of [`block_seed`]: far from the sampler's own streams.
pub const BLOCK_SEED_STREAM: u64 = 2_000_000;

/// The seed of block `index` of a stream seeded with `seed`.
pub fn block_seed(seed: u64, index: u64) -> u64 {
    word(seed, BLOCK_SEED_STREAM, index)
}

/// The fixed sizes of a stream's blocks, in frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlockSizes {
    /// Final frames of the previous block a block sees, kept exactly (`C`).
    pub context: usize,
    /// Frames a block holds back and the next one settles (`R`, the soft border).
    pub ramp: usize,
    /// Frames each block makes final (`B`, at least `C`).
    pub block: usize,
}

/// One block's window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    /// The stream frame of the window's first frame.
    pub start: usize,
    /// Frames in the window.
    pub frames: usize,
    /// Leading frames taken from the previous block (`C + R`; 0 for block 0).
    pub carried: usize,
    /// Frames before the ones this block finalises (`C`; 0 for block 0).
    pub context: usize,
}

impl Window {
    /// The window frames this block makes final.
    pub fn finalised(&self, sizes: &BlockSizes) -> std::ops::Range<usize> {
        self.context..self.context + sizes.block
    }
}

impl BlockSizes {
    /// The window of block `index`.
    pub fn window(&self, index: usize) -> Window {
        if index == 0 {
            Window {
                start: 0,
                frames: self.block + self.ramp,
                carried: 0,
                context: 0,
            }
        } else {
            Window {
                start: index * self.block - self.context,
                frames: self.context + self.ramp + self.block,
                carried: self.context + self.ramp,
                context: self.context,
            }
        }
    }

    /// Per window frame, how much of the previous block's frame is kept: 1 on the context, easing
    /// from 1 down to `1/R` over the held-back frames, 0 on new frames.
    pub fn carry_weights(&self, window: &Window) -> Vec<f32> {
        let keep: Vec<bool> = (0..window.frames).map(|i| i < window.carried).collect();
        if window.carried == 0 {
            return vec![0.0; window.frames];
        }
        soft_mask(&keep, self.ramp)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_finalise_every_frame_once_in_order() {
        let sizes = BlockSizes {
            context: 23,
            ramp: 10,
            block: 60,
        };
        let mut next = 0;
        for k in 0..5 {
            let w = sizes.window(k);
            let done = w.finalised(&sizes);
            assert_eq!(w.start + done.start, next, "block {k}");
            next = w.start + done.end;
            // The held-back frames of a block are the carried soft frames of the next one.
            let n = sizes.window(k + 1);
            assert_eq!(n.start + n.context, w.start + done.end);
            assert_eq!(n.start + n.carried, w.start + w.frames);
        }
        assert_eq!(next, 5 * 60);
    }

    #[test]
    fn carried_frames_ease_out_over_the_ramp() {
        let sizes = BlockSizes {
            context: 4,
            ramp: 3,
            block: 5,
        };
        let w = sizes.window(1);
        let weights = sizes.carry_weights(&w);
        assert_eq!(weights.len(), 12);
        // Context and the first held frame exactly 1, then 2/3 and 1/3, then new frames 0.
        let third = 1.0f32 / 3.0;
        assert_eq!(&weights[..5], &[1.0; 5]);
        assert!((weights[5] - 2.0 * third).abs() < 1e-6 && (weights[6] - third).abs() < 1e-6);
        assert_eq!(&weights[7..], &[0.0; 5]);
        assert_eq!(sizes.carry_weights(&sizes.window(0)), vec![0.0; 8]);
    }
}
