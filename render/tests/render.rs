//! Renders of a shipped clip, checked by decoding the pictures: size, frame count, a figure in
//! every frame, and a figure height that matches the skeleton's.

use std::path::PathBuf;

use sinmdm::bvh::{parse_bvh, read_bvh, to_bvh_string};
use sinmdm::motion::detect_up;
use sinmdm::motion::up::{UpAxis, reorient};
use sinmdm_render::figure::{FIGURE_COLOURS, projected_height};
use sinmdm_render::{Camera, Figure, RenderOptions, contact_sheet, gif_bytes};

fn walk() -> Figure {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/bvh/human_walk_cmu_131_01.bvh");
    let clip = read_bvh(path).unwrap();
    Figure::new(&clip.to_local(), UpAxis::PosY, "walk", 0.2)
}

/// The walk as a Z-up file, its up axis read from the motion.
fn z_up_walk() -> Figure {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/bvh/human_walk_cmu_131_01.bvh");
    let clip = read_bvh(path).unwrap();
    let copy = reorient(&clip.to_local(), &UpAxis::PosZ.file_from_canonical()).to_channels();
    let copy = parse_bvh(&to_bvh_string(&copy), "walk_zup.bvh").unwrap();
    let motion = copy.to_local();
    let up = detect_up(&motion).axis;
    assert_eq!(up, UpAxis::PosZ);
    Figure::new(&motion, up, "walk z-up", 0.2)
}

/// Rows spanned by pixels of `colour` in an RGBA frame of `width` pixels.
fn colour_rows(rgba: &[u8], width: usize, colour: [u8; 3]) -> Option<(usize, usize)> {
    let rows: Vec<usize> = rgba
        .chunks_exact(4)
        .enumerate()
        .filter(|(_, p)| p[..3] == colour)
        .map(|(i, _)| i / width)
        .collect();
    Some((*rows.iter().min()?, *rows.iter().max()?))
}

#[test]
fn gif_of_the_walk_has_a_figure_of_the_right_height_in_every_frame() {
    check_gif(walk());
}

#[test]
fn a_z_up_copy_is_drawn_upright_at_the_same_height() {
    let (upright, copy) = (walk(), z_up_walk());
    assert!((upright.height - copy.height).abs() < 1e-6 * upright.height);
    check_gif(copy);
}

fn check_gif(figure: Figure) {
    let options = RenderOptions::default();
    let bytes = gif_bytes(std::slice::from_ref(&figure), &options).unwrap();

    let mut decoder = gif::DecodeOptions::new();
    decoder.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = decoder.read_info(bytes.as_slice()).unwrap();
    assert_eq!((decoder.width(), decoder.height()), (320, 320));
    // 994 frames at 120 fps are written at 40 fps (every third frame).
    let mut frames = 0;
    let mut total_delay = 0u32;
    // The camera draws the skeleton height (standing, feet to head) as 60 % of the panel.
    let expected = 0.6 * 320.0;
    let mut tallest = 0f64;
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        total_delay += u32::from(frame.delay);
        let (top, bottom) = colour_rows(&frame.buffer, 320, FIGURE_COLOURS[0])
            .unwrap_or_else(|| panic!("no figure in frame {frames}"));
        assert!(
            bottom < 320 && top > 0,
            "frame {frames}: figure leaves the frame"
        );
        let drawn = (bottom - top) as f64;
        let projected = projected_height(&figure, frames * 3, &options);
        assert!(
            (drawn - projected).abs() < 12.0,
            "frame {frames}: figure {drawn} px high, projection says {projected}"
        );
        assert!(
            drawn > 0.5 * expected && drawn < 1.1 * expected,
            "frame {frames}: figure {drawn} px high for a skeleton drawn {expected} px tall"
        );
        tallest = tallest.max(drawn);
        frames += 1;
    }
    assert_eq!(frames, 994usize.div_ceil(3));
    // Upright, the figure is as tall as the skeleton, seen 15 degrees from above.
    assert!(
        (tallest / expected - 1.0).abs() < 0.08,
        "tallest figure {tallest} px, skeleton {expected} px"
    );
    // The GIF lasts as long as the clip (8.28 s), to a hundredth per frame at most.
    assert!(
        (f64::from(total_delay) / 100.0 - 994.0 / 120.0).abs() < 0.05,
        "{total_delay}"
    );
}

#[test]
fn png_contact_sheet_has_one_tile_per_frame_and_clip() {
    let figures = [walk(), walk()];
    let options = RenderOptions {
        panel_width: 100,
        panel_height: 120,
        camera: Camera::Fixed,
    };
    let sheet = contact_sheet(&figures, 5, &options);
    assert_eq!((sheet.width, sheet.height), (500, 240));
    for row in 0..2 {
        for tile in 0..5 {
            let figure_pixels = (row * 120..(row + 1) * 120)
                .flat_map(|y| (tile * 100..(tile + 1) * 100).map(move |x| (x, y)))
                .filter(|&(x, y)| sheet.get(x, y) == FIGURE_COLOURS[0])
                .count();
            assert!(figure_pixels > 50, "tile {tile} of row {row} has no figure");
        }
    }
    let png = sheet.to_png();
    assert_eq!(&png[1..4], b"PNG");
}
