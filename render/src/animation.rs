//! Animated GIFs of figures, at the clip's frame rate, with the renders' fixed palette.

use super::canvas::{Canvas, Rgb};
use super::figure::{Figure, RenderOptions, palette, render_frame};

/// A GIF that could not be made.
#[derive(Debug, thiserror::Error)]
pub enum AnimationError {
    /// The picture is larger than GIF allows (65 535 pixels a side).
    #[error("a {width} x {height} picture is too large for GIF")]
    TooLarge {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// The encoder failed.
    #[error("GIF encoding failed: {0}")]
    Encoding(String),
}

/// The highest frame rate a GIF is written at; faster clips skip frames.
pub const MAX_GIF_FPS: f64 = 50.0;

/// Frame delays in hundredths of a second that keep `fps` on average (GIF delays are whole
/// hundredths: 30 fps alternates 3, 3 and 4).
pub fn delays(frames: usize, fps: f64) -> Vec<u16> {
    let at = |i: usize| (i as f64 * 100.0 / fps).round() as i64;
    (0..frames)
        .map(|i| (at(i + 1) - at(i)).clamp(1, u16::MAX as i64) as u16)
        .collect()
}

/// Palette index of each pixel (the nearest palette colour).
fn indices(canvas: &Canvas, palette: &[Rgb]) -> Vec<u8> {
    let mut last: (Rgb, u8) = (palette[0], 0);
    canvas
        .pixels
        .chunks_exact(3)
        .map(|p| {
            let c = [p[0], p[1], p[2]];
            if c == last.0 {
                return last.1;
            }
            let best = palette
                .iter()
                .enumerate()
                .min_by_key(|(_, q)| {
                    (0..3)
                        .map(|k| (i32::from(c[k]) - i32::from(q[k])).pow(2))
                        .sum::<i32>()
                })
                .map_or(0, |(i, _)| i as u8);
            last = (c, best);
            best
        })
        .collect()
}

/// Renders every frame of the figures side by side and encodes them as a looping GIF at the
/// first figure's frame rate; returns the file's bytes.
pub fn gif_bytes(figures: &[Figure], options: &RenderOptions) -> Result<Vec<u8>, AnimationError> {
    let frames = figures.iter().map(Figure::frames).max().unwrap_or(0).max(1);
    let fps = figures.first().map_or(30.0, |f| f.fps);
    // GIF delays are whole hundredths and viewers slow down delays under 2: show every
    // `stride`-th frame of clips faster than 50 fps.
    let stride = (fps / MAX_GIF_FPS).ceil().max(1.0) as usize;
    let shown = frames.div_ceil(stride);
    let width = options.panel_width * figures.len().max(1);
    let height = options.panel_height;
    if width > u16::MAX as usize || height > u16::MAX as usize {
        return Err(AnimationError::TooLarge { width, height });
    }
    let colours = palette();
    let mut flat: Vec<u8> = colours.iter().flatten().copied().collect();
    while flat.len() < 16 * 3 {
        flat.push(0);
    }
    let fail = |e: gif::EncodingError| AnimationError::Encoding(e.to_string());
    let mut encoder =
        gif::Encoder::new(Vec::new(), width as u16, height as u16, &flat).map_err(fail)?;
    encoder.set_repeat(gif::Repeat::Infinite).map_err(fail)?;
    for (k, delay) in delays(shown, fps / stride as f64).into_iter().enumerate() {
        let canvas = render_frame(figures, k * stride, options);
        let mut out = gif::Frame::from_indexed_pixels(
            width as u16,
            height as u16,
            indices(&canvas, &colours),
            None,
        );
        out.delay = delay;
        encoder.write_frame(&out).map_err(fail)?;
    }
    encoder.into_inner().map_err(fail)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delays_keep_the_frame_rate_on_average() {
        let d = delays(30, 30.0);
        assert_eq!(d.iter().map(|&v| u32::from(v)).sum::<u32>(), 100);
        assert!(d.iter().all(|&v| v == 3 || v == 4));
        assert_eq!(delays(4, 25.0), vec![4, 4, 4, 4]);
    }
}
