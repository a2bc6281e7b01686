//! Streams on the small trained walk model: the motion does not depend on the chunk sizes asked
//! for, the root's travel carries on across seams, planted and raw streams share their
//! features, and poses supplied for composition are followed.

mod common;

use sinmdm::motion::fk::global_poses;
use sinmdm::{Feet, Model, Stream, StreamCompose, StreamOptions};

fn model() -> Model {
    common::tiny_model()
}

fn options(feet: Feet) -> StreamOptions {
    StreamOptions {
        seed: 5,
        steps: Some(3),
        block_frames: Some(30),
        feet,
        ..StreamOptions::default()
    }
}

/// `total` frames in chunks of the given sizes, cycling, as one motion's rotations,
/// translations and features.
fn run(model: &mut Model, feet: Feet, sizes: &[usize], total: usize) -> (Vec<f64>, Vec<f32>) {
    let mut stream = Stream::new(model.metadata(), options(feet)).unwrap();
    let (mut motion, mut features) = (Vec::new(), Vec::new());
    let mut made = 0;
    for &n in sizes.iter().cycle() {
        let n = n.min(total - made);
        let chunk = stream.next(model, n).unwrap();
        assert_eq!(chunk.frames(), n);
        motion.extend(chunk.motion.rotations.iter().flatten().flatten().copied());
        motion.extend(chunk.motion.translations.iter().flatten().copied());
        features.extend(chunk.features.t().iter().copied());
        made += n;
        if made == total {
            break;
        }
    }
    assert_eq!(stream.frames_handed_out(), total);
    (motion, features)
}

#[test]
fn chunk_sizes_do_not_change_the_motion() {
    let mut model = model();
    let one = run(&mut model, Feet::Planted, &[150], 150);
    let small = run(&mut model, Feet::Planted, &[1, 7, 30, 2], 150);
    // Chunks regroup frames: compare frame by frame through the features and the whole motion.
    assert_eq!(one.1, small.1);
    let mut a = one.0.clone();
    let mut b = small.0.clone();
    a.sort_by(f64::total_cmp);
    b.sort_by(f64::total_cmp);
    assert_eq!(a, b);
    // Raw feet: the same features.
    let raw = run(&mut model, Feet::Raw, &[150], 150);
    assert_eq!(one.1, raw.1);
}

#[test]
fn the_root_travels_on_across_seams_without_jumps() {
    let mut model = model();
    let mut stream = Stream::new(model.metadata(), options(Feet::Raw)).unwrap();
    let chunk = stream.next(&mut model, 150).unwrap();
    let poses = global_poses(&chunk.motion);
    let joints = model.skeleton().len();
    let root: Vec<_> = poses.iter().map(|p| p.joints[0]).collect();
    let steps: Vec<f64> = root
        .windows(2)
        .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][2] - w[0][2]).powi(2)).sqrt())
        .collect();
    let mut sorted = steps.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    // Seams after frames 30, 60, 90, 120: no step there is out of line with the rest.
    for seam in [30usize, 60, 90, 120] {
        assert!(
            steps[seam - 1] < 4.0 * median + 1e-9,
            "root step {} at seam {seam}, median {median}",
            steps[seam - 1]
        );
    }
    assert_eq!(chunk.motion.rotations.len(), 150 * joints);
}

#[test]
fn a_composed_stream_follows_the_supplied_root_path() {
    let mut model = model();
    // The supplied poses: a raw stream of another seed.
    let mut source = Stream::new(
        model.metadata(),
        StreamOptions {
            seed: 99,
            ..options(Feet::Raw)
        },
    )
    .unwrap();
    let guide = source.next(&mut model, 120).unwrap();
    let mut stream = Stream::new(
        model.metadata(),
        StreamOptions {
            compose: Some(StreamCompose {
                joints: vec![],
                root: true,
            }),
            ..options(Feet::Raw)
        },
    )
    .unwrap();
    stream.supply(&guide.poses()).unwrap();
    let out = stream.next(&mut model, 60).unwrap();
    // The root rows (displacements and height) follow the supplied ones away from the soft
    // border at the end of what was supplied.
    let roots = model.metadata().layout.root.as_ref().unwrap().axes.len();
    for row in 0..roots {
        for frame in 1..60 {
            let (got, want) = (out.features[[row, frame]], guide.features[[row, frame]]);
            assert!(
                (got - want).abs() < 1e-3,
                "row {row} frame {frame}: {got} vs {want}"
            );
        }
    }
    // A free stream of the same seed does not.
    let mut free = Stream::new(model.metadata(), options(Feet::Raw)).unwrap();
    let free = free.next(&mut model, 60).unwrap();
    assert!((0..60).any(|f| (free.features[[1, f]] - guide.features[[1, f]]).abs() > 1e-2));
}

#[test]
fn bad_stream_options_are_refused() {
    let model = model();
    let bad = |o: StreamOptions| Stream::new(model.metadata(), o).unwrap_err().to_string();
    assert!(
        bad(StreamOptions {
            block_frames: Some(5),
            ..options(Feet::Raw)
        })
        .contains("shorter than their")
    );
    assert!(
        bad(StreamOptions {
            compose: Some(StreamCompose::default()),
            ..options(Feet::Raw)
        })
        .contains("composition needs")
    );
}

#[test]
fn a_bvh_written_chunk_by_chunk_is_the_bvh_of_the_whole_motion() {
    use sinmdm::bvh::{BvhStreamWriter, to_bvh_string};
    let mut model = model();
    let dir = std::env::temp_dir().join(format!("sinmdm-stream-bvh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("chunked.bvh");
    let mut stream = Stream::new(model.metadata(), options(Feet::Planted)).unwrap();
    let mut writer = BvhStreamWriter::create(&path, model.skeleton(), model.fps(), 130).unwrap();
    let mut whole: Option<sinmdm::motion::LocalMotion> = None;
    for n in [17, 50, 1, 62] {
        let chunk = stream.next(&mut model, n).unwrap();
        writer.append(&chunk.motion).unwrap();
        match whole.as_mut() {
            None => whole = Some(chunk.motion),
            Some(w) => {
                w.rotations.extend(chunk.motion.rotations);
                w.translations.extend(chunk.motion.translations);
            }
        }
        // Nothing under the file's name until it is complete.
        assert!(!path.exists());
    }
    writer.finish().unwrap();
    let written = std::fs::read_to_string(&path).unwrap();
    assert_eq!(written, to_bvh_string(&whole.unwrap().to_channels()));
    // A writer dropped before its last frame leaves nothing behind.
    let partial = dir.join("partial.bvh");
    let mut writer = BvhStreamWriter::create(&partial, model.skeleton(), model.fps(), 10).unwrap();
    writer
        .append(&stream.next(&mut model, 5).unwrap().motion)
        .unwrap();
    assert!(
        writer
            .append(&stream.next(&mut model, 6).unwrap().motion)
            .is_err()
    );
    drop(writer);
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}
