//! Stick-figure renders of motion: forward kinematics, an orthographic camera from the front
//! left and above, a ground grid, contacts highlighted, several clips side by side.
//!
//! Figures are drawn in the canonical Y-up frame ([`sinmdm::motion::up`]): a Z-up clip is turned
//! upright first, so the camera and the grid never depend on the file's convention.

use super::canvas::{Canvas, Rgb};
use sinmdm::motion::contacts::{choose_contact_joints, label_contacts};
use sinmdm::motion::ground::Body;
use sinmdm::motion::math::Vec3;
use sinmdm::motion::up::{GROUND_PLANE, UpAxis, on_ground, to_canonical};
use sinmdm::motion::{GlobalPose, LocalMotion, global_poses};

/// Background colour.
pub const BACKGROUND: Rgb = [250, 250, 246];
/// Ground grid colour.
pub const GRID: Rgb = [205, 205, 198];
/// Colours of the figures, one per panel in turn.
pub const FIGURE_COLOURS: [Rgb; 4] = [[40, 70, 160], [30, 120, 80], [150, 60, 120], [170, 100, 20]];
/// Colour of what was kept from a reference (in-betweens, compositions).
pub const KEPT: Rgb = [200, 60, 40];
/// A foot on the ground.
pub const CONTACT: Rgb = [230, 150, 0];
/// Text colour.
pub const TEXT: Rgb = [60, 60, 60];

/// Every colour a render uses (its GIF palette).
pub fn palette() -> Vec<Rgb> {
    let mut p = vec![BACKGROUND, GRID, KEPT, CONTACT, TEXT];
    p.extend(FIGURE_COLOURS);
    p
}

/// How the camera moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Camera {
    /// Centred on the root's ground position at every frame.
    Follow,
    /// Still, framing the whole path of the root.
    Fixed,
}

/// One clip to draw.
#[derive(Debug, Clone)]
pub struct Figure {
    /// Global joint positions per frame, in the canonical Y-up frame.
    pub poses: Vec<GlobalPose>,
    /// Parent of each joint.
    pub parents: Vec<Option<usize>>,
    /// Frames per second.
    pub fps: f64,
    /// Skeleton height in file units.
    pub height: f64,
    /// Lowest point of the clip (the ground).
    pub ground: f64,
    /// Contact joints with their per-frame labels.
    pub contacts: Vec<(usize, Vec<bool>)>,
    /// Per frame and joint: drawn in the "kept" colour (reference parts of a task's output).
    pub kept: Option<Vec<Vec<bool>>>,
    /// Label drawn in the panel's corner.
    pub label: String,
}

impl Figure {
    /// A figure of `motion` (in the frame of a file whose up axis is `up`), with contact joints
    /// found as the encoder finds them and labels from the speed threshold (in skeleton heights
    /// per second).
    pub fn new(
        motion: &LocalMotion,
        up: UpAxis,
        label: impl Into<String>,
        contact_speed: f64,
    ) -> Figure {
        let poses = global_poses(&to_canonical(motion, up));
        let body = Body::travelling(&motion.skeleton, &poses);
        let root = body.carrier();
        let height = body.height(&poses).max(1e-9);
        let ground = poses
            .iter()
            .map(|p| body.lowest_point(p))
            .fold(f64::INFINITY, f64::min);
        let joints = choose_contact_joints(&motion.skeleton, &poses, height, 0.25);
        let labelled = label_contacts(&poses, root, &joints, motion.fps, height, contact_speed);
        let contacts = joints
            .into_iter()
            .zip(labelled.labels)
            .map(|(j, labels)| (j, labels.into_iter().map(|l| l > 0.5).collect()))
            .collect();
        Figure {
            parents: motion.skeleton.joints.iter().map(|j| j.parent).collect(),
            poses,
            fps: motion.fps,
            height,
            ground: if ground.is_finite() { ground } else { 0.0 },
            contacts,
            kept: None,
            label: label.into(),
        }
    }

    /// Frames in the clip.
    pub fn frames(&self) -> usize {
        self.poses.len()
    }

    fn root_ground(&self, frame: usize) -> Vec3 {
        on_ground(self.poses[frame].joints[0], self.ground)
    }
}

/// Size and camera of a render.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Width of one panel in pixels.
    pub panel_width: usize,
    /// Height of a panel in pixels.
    pub panel_height: usize,
    /// Camera behaviour.
    pub camera: Camera,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            panel_width: 320,
            panel_height: 320,
            camera: Camera::Follow,
        }
    }
}

/// The orthographic view: screen right and up vectors in the canonical frame (Y up), looking
/// from the front left and slightly above.
fn view_axes() -> (Vec3, Vec3) {
    let (azimuth, elevation) = (35f64.to_radians(), 15f64.to_radians());
    let right = Vec3::new(azimuth.cos(), 0.0, -azimuth.sin());
    let forward = Vec3::new(
        azimuth.sin() * elevation.cos(),
        -elevation.sin(),
        azimuth.cos() * elevation.cos(),
    );
    // Perpendicular to both, with a positive Y component.
    let up = forward.cross(right);
    (right, up)
}

/// Maps world points of one figure to pixels of its panel.
struct Projection {
    centre: Vec3,
    scale: f64,
    origin: (f64, f64),
    right: Vec3,
    up: Vec3,
}

impl Projection {
    fn to_screen(&self, p: Vec3) -> (f64, f64) {
        let d = p - self.centre;
        (
            self.origin.0 + d.dot(self.right) * self.scale,
            self.origin.1 - d.dot(self.up) * self.scale,
        )
    }
}

fn projection(figure: &Figure, frame: usize, options: &RenderOptions) -> Projection {
    let (right, up) = view_axes();
    let (w, h) = (options.panel_width as f64, options.panel_height as f64);
    let origin = (w / 2.0, h * 0.78);
    match options.camera {
        Camera::Follow => Projection {
            centre: figure.root_ground(frame),
            scale: h * 0.6 / figure.height,
            origin,
            right,
            up,
        },
        Camera::Fixed => {
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for f in 0..figure.frames() {
                let r = figure.root_ground(f);
                for (i, axis) in GROUND_PLANE.into_iter().enumerate() {
                    lo[i] = lo[i].min(r[axis]);
                    hi[i] = hi[i].max(r[axis]);
                }
            }
            let mut centre = [0.0; 3];
            for (i, axis) in GROUND_PLANE.into_iter().enumerate() {
                centre[axis] = (lo[i] + hi[i]) / 2.0;
            }
            let centre = on_ground(Vec3(centre), figure.ground);
            let extent = (hi[0] - lo[0]).hypot(hi[1] - lo[1]) + figure.height;
            Projection {
                centre,
                scale: (w * 0.9 / extent).min(h * 0.6 / figure.height),
                origin,
                right,
                up,
            }
        }
    }
}

fn draw_grid(canvas: &mut Canvas, figure: &Figure, view: &Projection) {
    let step = figure.height / 2.0;
    let reach = 8;
    let snap = |v: f64| (v / step).round() * step;
    let (cx, cz) = (snap(view.centre[0]), snap(view.centre[2]));
    let y = figure.ground;
    for i in -reach..=reach {
        let o = i as f64 * step;
        let span = reach as f64 * step;
        let (a, b) = (
            view.to_screen(Vec3([cx + o, y, cz - span])),
            view.to_screen(Vec3([cx + o, y, cz + span])),
        );
        canvas.line(a.0, a.1, b.0, b.1, 1.0, GRID);
        let (a, b) = (
            view.to_screen(Vec3([cx - span, y, cz + o])),
            view.to_screen(Vec3([cx + span, y, cz + o])),
        );
        canvas.line(a.0, a.1, b.0, b.1, 1.0, GRID);
    }
}

fn draw_figure(
    canvas: &mut Canvas,
    figure: &Figure,
    frame: usize,
    view: &Projection,
    colour: Rgb,
    thickness: f64,
) {
    let pose = &figure.poses[frame];
    let kept = |joint: usize| {
        figure
            .kept
            .as_ref()
            .is_some_and(|k| k.get(frame).is_some_and(|row| row[joint]))
    };
    for (j, parent) in figure.parents.iter().enumerate() {
        if let Some(p) = *parent {
            let (a, b) = (
                view.to_screen(pose.joints[p]),
                view.to_screen(pose.joints[j]),
            );
            let c = if kept(j) { KEPT } else { colour };
            canvas.line(a.0, a.1, b.0, b.1, thickness, c);
        }
    }
    for &(j, tip) in &pose.end_sites {
        let (a, b) = (view.to_screen(pose.joints[j]), view.to_screen(tip));
        let c = if kept(j) { KEPT } else { colour };
        canvas.line(a.0, a.1, b.0, b.1, thickness, c);
    }
    for (joint, labels) in &figure.contacts {
        if labels.get(frame).copied().unwrap_or(false) {
            let (x, y) = view.to_screen(pose.contact_point(*joint));
            canvas.disc(x, y, thickness * 1.6, CONTACT);
        }
    }
    let head = view.to_screen(pose.joints[0]);
    canvas.disc(head.0, head.1, thickness * 1.2, colour);
}

/// Frame `frame` of every figure side by side (a figure shorter than `frame` holds its last
/// pose).
pub fn render_frame(figures: &[Figure], frame: usize, options: &RenderOptions) -> Canvas {
    let mut canvas = Canvas::new(
        options.panel_width * figures.len().max(1),
        options.panel_height,
        BACKGROUND,
    );
    let thickness = (options.panel_height as f64 / 120.0).max(1.5);
    for (i, figure) in figures.iter().enumerate() {
        if figure.frames() == 0 {
            continue;
        }
        let f = frame.min(figure.frames() - 1);
        let left = i * options.panel_width;
        // Each panel is drawn on its own canvas, so nothing spills into its neighbours.
        let view = projection(figure, f, options);
        let mut panel = Canvas::new(options.panel_width, options.panel_height, BACKGROUND);
        draw_grid(&mut panel, figure, &view);
        draw_figure(
            &mut panel,
            figure,
            f,
            &view,
            FIGURE_COLOURS[i % FIGURE_COLOURS.len()],
            thickness,
        );
        panel.text(4, 4, &figure.label.to_uppercase(), 1, TEXT);
        panel.text(
            4,
            options.panel_height as i64 - 12,
            &format!("{:.2}S", f as f64 / figure.fps),
            1,
            TEXT,
        );
        for y in 0..options.panel_height {
            let from = y * options.panel_width * 3;
            let to = (y * canvas.width + left) * 3;
            canvas.pixels[to..to + options.panel_width * 3]
                .copy_from_slice(&panel.pixels[from..from + options.panel_width * 3]);
        }
    }
    canvas
}

/// A contact sheet: `count` evenly spaced frames, one row per figure.
pub fn contact_sheet(figures: &[Figure], count: usize, options: &RenderOptions) -> Canvas {
    let count = count.max(1);
    let (w, h) = (options.panel_width, options.panel_height);
    let mut sheet = Canvas::new(w * count, h * figures.len().max(1), BACKGROUND);
    for (row, figure) in figures.iter().enumerate() {
        let n = figure.frames().max(1);
        // Only the first tile of a row carries the label.
        let mut unlabelled = figure.clone();
        unlabelled.label.clear();
        for k in 0..count {
            let frame = if count == 1 {
                0
            } else {
                k * (n - 1) / (count - 1)
            };
            let tile_figure = if k == 0 { figure } else { &unlabelled };
            let tile = render_frame(std::slice::from_ref(tile_figure), frame, options);
            for y in 0..h {
                let from = y * w * 3;
                let to = ((row * h + y) * sheet.width + k * w) * 3;
                sheet.pixels[to..to + w * 3].copy_from_slice(&tile.pixels[from..from + w * 3]);
            }
        }
    }
    sheet
}

/// Projected height in pixels of the figure at `frame` (highest to lowest drawn point) under
/// the renders' camera: for tests and framing checks.
pub fn projected_height(figure: &Figure, frame: usize, options: &RenderOptions) -> f64 {
    let view = projection(figure, frame, options);
    let ys: Vec<f64> = figure.poses[frame]
        .points()
        .map(|p| view.to_screen(p).1)
        .collect();
    let top = ys.iter().copied().fold(f64::INFINITY, f64::min);
    let bottom = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    bottom - top
}
