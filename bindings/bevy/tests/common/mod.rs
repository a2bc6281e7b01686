//! Shared by the headless tests: a headless app with the plugin, forward kinematics written out
//! in f64, and directions of travel.
#![allow(dead_code)]

use std::path::PathBuf;
use std::time::Duration;

use bevy_app::{App, TaskPoolPlugin};
use bevy_ecs::prelude::*;
use bevy_math::Vec3;
use bevy_time::{TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use bevy_transform::components::Transform;
use sinmdm::Pose;
use sinmdm_bevy::{CharacterOptions, MotionModel, SinmdmPlugin};

pub const BEVY_FPS: f64 = 60.0;

pub fn model_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../onnx-models")
        .join(name)
}

/// A headless app with the plugin, stepping 1/60 s a frame.
pub fn headless_app() -> App {
    let mut app = App::new();
    app.add_plugins((
        TaskPoolPlugin::default(),
        TimePlugin,
        TransformPlugin,
        SinmdmPlugin,
    ));
    app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
        1.0 / BEVY_FPS,
    )));
    app
}

/// A headless app stepping 1/60 s a frame, with a character of `model` at `place`.
pub fn app_with(model: &MotionModel, options: CharacterOptions, place: Transform) -> (App, Entity) {
    let mut app = headless_app();
    let world = app.world_mut();
    let mut commands = world.commands();
    let character = sinmdm_bevy::spawn_character(&mut commands, model, options, place)
        .expect("the character spawns");
    world.flush();
    (app, character)
}

/// A rotation matrix (rows) of a unit quaternion, in f64.
pub fn matrix(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [x, y, z, w] = q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

pub fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            m[r][c] = (0..3).map(|k| a[r][k] * b[k][c]).sum();
        }
    }
    m
}

pub fn apply(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| (0..3).map(|k| m[r][k] * v[k]).sum())
}

/// Spherical interpolation along the shorter arc, written out (f64).
pub fn slerp(a: [f64; 4], b: [f64; 4], t: f64) -> [f64; 4] {
    let mut dot: f64 = (0..4).map(|i| a[i] * b[i]).sum();
    let b = if dot < 0.0 {
        dot = -dot;
        b.map(|v| -v)
    } else {
        b
    };
    if dot > 0.9995 {
        let q: [f64; 4] = [0, 1, 2, 3].map(|i| a[i] + (b[i] - a[i]) * t);
        let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        return q.map(|v| v / n);
    }
    let theta = dot.clamp(-1.0, 1.0).acos();
    let (wa, wb) = (
        ((1.0 - t) * theta).sin() / theta.sin(),
        (t * theta).sin() / theta.sin(),
    );
    [0, 1, 2, 3].map(|i| wa * a[i] + wb * b[i])
}

/// World positions of every joint of the pose a fraction `t` from `a` to `b`, by forward
/// kinematics in f64: the character's placement, then the file-to-Bevy turn and the unit scale
/// on the top joints, then each joint's local transform.
pub fn world_positions(
    parents: &[Option<usize>],
    a: &Pose,
    b: &Pose,
    t: f64,
    place: (&[[f64; 3]; 3], [f64; 3]),
    turn: &[[f64; 3]; 3],
    scale: f64,
) -> Vec<[f64; 3]> {
    let f = |v: [f32; 3]| v.map(f64::from);
    let mut rotations: Vec<[[f64; 3]; 3]> = Vec::new();
    let mut positions: Vec<[f64; 3]> = Vec::new();
    for (j, parent) in parents.iter().enumerate() {
        let qa = a.rotations[j];
        let qb = b.rotations[j];
        let q = slerp(
            [qa.x, qa.y, qa.z, qa.w].map(f64::from),
            [qb.x, qb.y, qb.z, qb.w].map(f64::from),
            t,
        );
        let (ta, tb) = (f(a.translations[j]), f(b.translations[j]));
        let local_t: [f64; 3] = [0, 1, 2].map(|i| (ta[i] + (tb[i] - ta[i]) * t) * scale);
        let (parent_rot, parent_pos, local_t, local_r) = match parent {
            Some(p) => (rotations[*p], positions[*p], local_t, matrix(q)),
            None => (
                *place.0,
                place.1,
                apply(turn, local_t),
                mul(turn, &matrix(q)),
            ),
        };
        let offset = apply(&parent_rot, local_t);
        positions.push([0, 1, 2].map(|i| parent_pos[i] + offset[i]));
        rotations.push(mul(&parent_rot, &local_r));
    }
    positions
}

/// Directions of travel on the ground (radians about up, from +Z toward +X) of the root, one per
/// Bevy frame, each over the second around it.
pub fn travel_headings(roots: &[Vec3]) -> Vec<Option<f64>> {
    let half = HEADING_HALF_WINDOW;
    (0..roots.len())
        .map(|k| {
            let (a, b) = (roots.get(k.checked_sub(half)?)?, roots.get(k + half)?);
            let d = *b - *a;
            (d.x.hypot(d.z) > 1e-3).then(|| f64::from(d.x).atan2(f64::from(d.z)))
        })
        .collect()
}

/// Bevy frames either side of a frame over which its direction of travel is measured: half a
/// second, longer than a stride's sway.
pub const HEADING_HALF_WINDOW: usize = (BEVY_FPS / 2.0) as usize;

/// The direction of travel unwrapped: each frame's heading as the sum of the turns since the
/// first measured frame (so a full turn left reads 2 pi, not 0), `None` where unmeasured.
pub fn unwrapped(headings: &[Option<f64>]) -> Vec<Option<f64>> {
    let mut total = None::<f64>;
    let mut last = None::<f64>;
    headings
        .iter()
        .map(|h| {
            let h = (*h)?;
            total = Some(match (total, last) {
                (Some(t), Some(l)) => t + signed_angle(h, l),
                _ => h,
            });
            last = Some(h);
            total
        })
        .collect()
}

/// `a - b` wrapped into (-pi, pi]: positive when `a` is turned left of `b` (headings measured
/// from +Z toward +X, which a left turn about +Y increases).
pub fn signed_angle(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI {
        d - std::f64::consts::TAU
    } else {
        d
    }
}
