//! Crowds on real models through onnxruntime: a character's motion is the same bits alone, in
//! a crowd of 8 and of 200, on one thread and on two, whoever joins or leaves beside it, and
//! steered characters follow their own commands.

mod common;

use sinmdm::steer::SteerFrame;
use sinmdm::{
    CharacterId, Crowd, Feet, Model, ModelOptions, OneCallPerThread, Stream, StreamOptions,
    TaskError,
};

fn tiny(threads: usize) -> Model {
    Model::open(
        common::workspace().join("tests/data/models/walk_tiny.onnx"),
        &ModelOptions {
            threads: Some(threads),
        },
    )
    .expect("the test model opens (run scripts/setup.sh first)")
}

/// Character `i`'s options: seeds, feet, steps and blocks differ from character to character,
/// so a crowd's blocks have windows of several lengths at once.
fn options(i: usize) -> StreamOptions {
    StreamOptions {
        seed: 100 + i as u64,
        steps: Some(2 + i % 3),
        block_frames: Some(24 + 6 * (i % 2)),
        feet: if i.is_multiple_of(2) {
            Feet::Planted
        } else {
            Feet::Raw
        },
        ..StreamOptions::default()
    }
}

/// Every number of a chunk's motion and features, as bits, frame after frame (so chunks of any
/// size concatenate to the same list).
fn bits(chunk: &sinmdm::StreamChunk) -> Vec<u64> {
    let m = &chunk.motion;
    let joints = m.skeleton.len();
    let mut out = Vec::new();
    for frame in 0..chunk.frames() {
        let range = frame * joints..(frame + 1) * joints;
        out.extend(
            m.rotations[range.clone()]
                .iter()
                .flatten()
                .flatten()
                .map(|v| v.to_bits()),
        );
        out.extend(m.translations[range].iter().flatten().map(|v| v.to_bits()));
        out.extend(
            chunk
                .features
                .column(frame)
                .iter()
                .map(|v| u64::from(v.to_bits())),
        );
    }
    out
}

/// `frames` frames of character `i` alone, read in chunks of `chunk`.
fn alone(model: &mut Model, i: usize, frames: usize, chunk: usize) -> Vec<u64> {
    let mut stream = Stream::new(model.metadata(), options(i)).unwrap();
    let mut out = Vec::new();
    let mut made = 0;
    while made < frames {
        let n = chunk.min(frames - made);
        out.extend(bits(&stream.next(model, n).unwrap()));
        made += n;
    }
    out
}

/// [`crowd`] with the crowd's blocks denoised in one onnxruntime call per thread.
fn crowd_one_call(model: &mut Model, size: usize, frames: usize, chunk: usize) -> Vec<Vec<u64>> {
    let mut crowd = Crowd::new(model.metadata());
    for i in 0..size {
        crowd.join(options(i)).unwrap();
    }
    let mut batched = OneCallPerThread(model);
    let mut out = vec![Vec::new(); size];
    let mut made = 0;
    while made < frames {
        let n = chunk.min(frames - made);
        crowd.prepare(&mut batched, 3 * size, n + 5).unwrap();
        for (k, (_, part)) in crowd.next(&mut batched, n).unwrap().into_iter().enumerate() {
            out[k].extend(bits(&part));
        }
        made += n;
    }
    out
}

/// `frames` frames of every character of a crowd of `size` (character `i` with
/// [`options`]`(i)`), read in chunks of `chunk` with `prepare` between reads.
fn crowd(model: &mut Model, size: usize, frames: usize, chunk: usize) -> Vec<Vec<u64>> {
    let mut crowd = Crowd::new(model.metadata());
    let ids: Vec<CharacterId> = (0..size).map(|i| crowd.join(options(i)).unwrap()).collect();
    let mut out = vec![Vec::new(); size];
    let mut made = 0;
    while made < frames {
        let n = chunk.min(frames - made);
        crowd.prepare(model, 1, n + 5).unwrap();
        for (k, (id, part)) in crowd.next(model, n).unwrap().into_iter().enumerate() {
            assert_eq!(id, ids[k]);
            assert_eq!(part.frames(), n);
            out[k].extend(bits(&part));
        }
        made += n;
    }
    out
}

#[test]
fn a_character_is_the_same_bits_alone_and_in_crowds_of_8_and_200_on_1_and_2_threads() {
    let frames = 70;
    let mut one = tiny(1);
    let watched = [0, 1, 5, 7];
    let expected: Vec<Vec<u64>> = watched
        .iter()
        .map(|&i| alone(&mut one, i, frames, 70))
        .collect();
    for threads in [1, 2] {
        let mut model = tiny(threads);
        for size in [1, 8, 200] {
            let got = crowd(&mut model, size, frames, 9);
            for (&i, want) in watched.iter().zip(&expected) {
                if i < size {
                    assert!(
                        &got[i] == want,
                        "character {i} in a crowd of {size} on {threads} threads differs from it alone"
                    );
                }
            }
        }
    }
}

#[test]
fn joining_and_leaving_do_not_change_the_others() {
    let mut model = tiny(2);
    let frames = 60;
    let want: Vec<Vec<u64>> = (0..4).map(|i| alone(&mut model, i, frames, 60)).collect();
    let mut crowd = Crowd::new(model.metadata());
    let first = crowd.join(options(0)).unwrap();
    let mut got = vec![Vec::new(); 4];
    let mut ids = vec![first];
    let mut left = None;
    for frame in 0..frames {
        // Characters 1-3 join on frames 7, 19 and 31; a stranger joins at 11 and leaves at 40.
        if [7, 19, 31].contains(&frame) {
            ids.push(crowd.join(options(ids.len())).unwrap());
        }
        if frame == 11 {
            left = Some(crowd.join(options(9)).unwrap());
        }
        if frame == 40 {
            let gone = crowd
                .leave(left.unwrap())
                .expect("the stranger is in the crowd");
            assert_eq!(gone.frames_handed_out(), 29);
            assert!(crowd.leave(left.unwrap()).is_none());
        }
        crowd.prepare(&mut model, 2, 4).unwrap();
        for (id, chunk) in crowd.next(&mut model, 1).unwrap() {
            if let Some(k) = ids.iter().position(|&c| c == id) {
                got[k].extend(bits(&chunk));
            }
        }
    }
    let per_frame = want[0].len() / frames;
    assert_eq!(got[0], want[0], "the first character");
    for (k, joined) in [(1, 7), (2, 19), (3, 31)] {
        let made = frames - joined;
        assert_eq!(
            got[k],
            want[k][..made * per_frame],
            "character {k}, joined at frame {joined}"
        );
    }
}

#[test]
fn prepare_makes_frames_ahead_within_its_steps_the_most_urgent_first() {
    let mut model = tiny(1);
    let mut crowd = Crowd::new(model.metadata());
    for i in 0..3 {
        crowd.join(options(i)).unwrap();
    }
    // Each character needs 2-4 steps for its first block: a step each makes nothing ready.
    let progress = crowd.prepare(&mut model, 3, 10).unwrap();
    assert_eq!(progress.steps, 3);
    assert_eq!(progress.waiting, 3);
    // A budget of one step goes to the most urgent (fewest ready, then first joined).
    let progress = crowd.prepare(&mut model, 1, 10).unwrap();
    assert_eq!(progress.steps, 1);
    assert!(
        crowd
            .character(sinmdm::CharacterId(0))
            .unwrap()
            .ready_frames()
            >= 10
    );
    assert_eq!(crowd.prepare(&mut model, 100, 10).unwrap().waiting, 0);
    for id in crowd.ids().collect::<Vec<_>>() {
        assert!(crowd.character(id).unwrap().ready_frames() >= 10);
    }
    // Nothing is short: no step is taken.
    assert_eq!(crowd.prepare(&mut model, 100, 10).unwrap().steps, 0);
}

#[test]
fn steered_characters_follow_their_own_commands_as_they_would_alone() {
    let mut model = Model::open(
        common::workspace().join("onnx-models/human_walk_cmu.onnx"),
        &ModelOptions { threads: Some(2) },
    )
    .expect("run scripts/setup.sh first");
    let fps = model.metadata().layout.fps;
    let frames = 90;
    let options = |i: usize| StreamOptions {
        seed: i as u64,
        steps: Some(4),
        block_frames: Some(40),
        ..StreamOptions::default()
    };
    let commands = |i: usize| -> Vec<SteerFrame> {
        (0..frames + 200)
            .map(|_| SteerFrame::Velocity {
                forward: 10.0 + i as f64,
                turn: (i as f64 - 2.0) * 0.2,
            })
            .collect()
    };
    let mut want = Vec::new();
    for i in 0..5 {
        let mut stream = Stream::new(model.metadata(), options(i)).unwrap();
        stream.steer(&commands(i)).unwrap();
        want.push(bits(&stream.next(&mut model, frames).unwrap()));
    }
    let mut crowd = Crowd::new(model.metadata());
    for i in 0..5 {
        let id = crowd.join(options(i)).unwrap();
        crowd
            .character_mut(id)
            .unwrap()
            .steer(&commands(i))
            .unwrap();
    }
    let mut got = vec![Vec::new(); 5];
    for _ in 0..frames / 30 {
        for (k, (_, chunk)) in crowd.next(&mut model, 30).unwrap().into_iter().enumerate() {
            got[k].extend(bits(&chunk));
        }
    }
    for i in 0..5 {
        assert!(got[i] == want[i], "steered character {i} at {fps} fps");
    }
    // The characters turn by their own commands: not one motion five times.
    assert!(got.windows(2).all(|w| w[0] != w[1]));
}

#[test]
fn a_character_s_bad_options_are_refused_when_it_joins() {
    let model = tiny(1);
    let mut crowd = Crowd::new(model.metadata());
    let bad = StreamOptions {
        block_frames: Some(1),
        ..StreamOptions::default()
    };
    let err = crowd.join(bad).unwrap_err();
    assert!(matches!(err, TaskError::Stream(_)), "{err}");
    assert!(crowd.is_empty());
}

#[test]
fn preparing_some_characters_steps_none_of_the_others() {
    let mut model = tiny(1);
    let mut crowd = Crowd::new(model.metadata());
    let ids: Vec<CharacterId> = (0..4).map(|i| crowd.join(options(i)).unwrap()).collect();
    let chosen = [ids[1], ids[3], CharacterId(99)];
    let progress = crowd
        .prepare_characters(&mut model, &chosen, usize::MAX, 10)
        .unwrap();
    assert_eq!(progress.waiting, 0);
    // Characters 1 and 3 take 3 and 2 steps (2 + i % 3) for their first blocks.
    assert_eq!(progress.steps, 5);
    let ready = |k: usize| crowd.character(ids[k]).unwrap().ready_frames();
    assert_eq!((ready(0), ready(2)), (0, 0));
    assert!(ready(1) >= 10 && ready(3) >= 10);
    assert_eq!(crowd.character(ids[0]).unwrap().block_progress().total, 0);
}

#[test]
fn one_call_per_thread_keeps_each_character_s_bits_here() {
    // onnxruntime does not promise it (so it is an opt-in); this checks it holds here.
    let frames = 50;
    let mut one = tiny(1);
    let watched = [0, 4, 13];
    let expected: Vec<Vec<u64>> = watched
        .iter()
        .map(|&i| alone(&mut one, i, frames, frames))
        .collect();
    for threads in [1, 2] {
        let mut model = tiny(threads);
        let got = crowd_one_call(&mut model, 16, frames, 7);
        for (&i, want) in watched.iter().zip(&expected) {
            assert!(
                &got[i] == want,
                "character {i} batched on {threads} threads differs from it alone"
            );
        }
    }
}
