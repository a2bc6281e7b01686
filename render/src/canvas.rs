//! An RGB raster with the few drawing operations the pictures need, and PNG output.

use std::path::Path;

use super::font;

/// An RGB colour.
pub type Rgb = [u8; 3];

/// A width x height RGB image, row-major from the top-left corner.
#[derive(Debug, Clone, PartialEq)]
pub struct Canvas {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width * height * 3` bytes.
    pub pixels: Vec<u8>,
}

impl Canvas {
    /// A canvas filled with `background`.
    pub fn new(width: usize, height: usize, background: Rgb) -> Canvas {
        let mut pixels = Vec::with_capacity(width * height * 3);
        for _ in 0..width * height {
            pixels.extend_from_slice(&background);
        }
        Canvas {
            width,
            height,
            pixels,
        }
    }

    /// The colour at `(x, y)`.
    pub fn get(&self, x: usize, y: usize) -> Rgb {
        let i = (y * self.width + x) * 3;
        [self.pixels[i], self.pixels[i + 1], self.pixels[i + 2]]
    }

    /// Sets `(x, y)` when it is inside the canvas.
    pub fn set(&mut self, x: i64, y: i64, colour: Rgb) {
        if x >= 0 && y >= 0 && (x as usize) < self.width && (y as usize) < self.height {
            let i = (y as usize * self.width + x as usize) * 3;
            self.pixels[i..i + 3].copy_from_slice(&colour);
        }
    }

    /// A filled axis-aligned rectangle.
    pub fn fill_rect(&mut self, x: i64, y: i64, w: i64, h: i64, colour: Rgb) {
        for yy in y..y + h {
            for xx in x..x + w {
                self.set(xx, yy, colour);
            }
        }
    }

    /// A line `thickness` pixels wide from `(x0, y0)` to `(x1, y1)` (clipped to the canvas).
    pub fn line(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, thickness: f64, colour: Rgb) {
        if !(x0.is_finite() && y0.is_finite() && x1.is_finite() && y1.is_finite()) {
            return;
        }
        let length = (x1 - x0).hypot(y1 - y0);
        let steps = (length.ceil() as usize).clamp(1, 100_000);
        let r = (thickness / 2.0).max(0.5);
        for s in 0..=steps {
            let f = s as f64 / steps as f64;
            self.disc(x0 + (x1 - x0) * f, y0 + (y1 - y0) * f, r, colour);
        }
    }

    /// A filled disc of radius `r` around `(cx, cy)`.
    pub fn disc(&mut self, cx: f64, cy: f64, r: f64, colour: Rgb) {
        if !(cx.is_finite() && cy.is_finite()) {
            return;
        }
        let reach = r.ceil() as i64;
        let (ix, iy) = (cx.round() as i64, cy.round() as i64);
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                let (x, y) = (ix + dx, iy + dy);
                if (x as f64 - cx).powi(2) + (y as f64 - cy).powi(2) <= r * r + 0.25 {
                    self.set(x, y, colour);
                }
            }
        }
    }

    /// Text in the 5x7 font with its top-left corner at `(x, y)`, each font pixel `scale` wide.
    pub fn text(&mut self, x: i64, y: i64, text: &str, scale: i64, colour: Rgb) {
        for (k, c) in text.chars().enumerate() {
            let rows = font::glyph(c);
            let left = x + k as i64 * font::ADVANCE as i64 * scale;
            for (row, bits) in rows.iter().enumerate() {
                for col in 0..5 {
                    if bits & (0x10 >> col) != 0 {
                        self.fill_rect(
                            left + col * scale,
                            y + row as i64 * scale,
                            scale,
                            scale,
                            colour,
                        );
                    }
                }
            }
        }
    }

    /// Width in pixels of `text` at `scale`.
    pub fn text_width(text: &str, scale: i64) -> i64 {
        (text.chars().count() * font::ADVANCE) as i64 * scale
    }

    /// Encodes the canvas as PNG bytes.
    pub fn to_png(&self) -> Vec<u8> {
        let mut bytes = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut bytes, self.width as u32, self.height as u32);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header().expect("writing to memory");
            writer
                .write_image_data(&self.pixels)
                .expect("pixel count matches the header");
        }
        bytes
    }

    /// Writes the canvas as a PNG file, atomically.
    pub fn write_png(&self, path: &Path) -> std::io::Result<()> {
        sinmdm::files::write_atomically(path, &self.to_png())
    }
}
