//! Runs and streams spread over a game's frames: stepping a run 1, 3 or all steps at a time, a
//! cancelled and resumed run, a stream prepared ahead, all give the bits of the one-call run;
//! and a sample's bits do not depend on the model's thread count or its place in the batch.

use std::ops::ControlFlow;
use std::path::PathBuf;

use ndarray::{Array3, ArrayView3, s};
use sinmdm::{
    Denoiser, Feet, Model, ModelError, ModelOptions, Request, Run, Span, Stream, StreamOptions,
    Task, TaskError,
};

fn model_with(threads: usize) -> Model {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../onnx-models/human_walk_cmu.onnx");
    Model::open(
        path,
        &ModelOptions {
            threads: Some(threads),
        },
    )
    .expect("run scripts/setup.sh first")
}

/// A model that counts its calls.
struct Counting<'a> {
    model: &'a mut Model,
    calls: usize,
}

impl Denoiser for Counting<'_> {
    type Error = ModelError;
    fn features(&self) -> usize {
        self.model.features()
    }
    fn denoise(&mut self, x_t: ArrayView3<'_, f32>, t: &[i64]) -> Result<Array3<f32>, ModelError> {
        self.calls += 1;
        self.model.denoise(x_t, t)
    }
}

fn go() -> impl FnMut(usize, usize) -> ControlFlow<()> {
    |_, _| ControlFlow::Continue(())
}

fn request(model: &Model, task: Task, count: usize) -> Request {
    let _ = model;
    Request {
        task,
        count,
        seed: 21,
        steps: Some(9),
        feet: Feet::Planted,
        method: Default::default(),
    }
}

fn inbetween(model: &mut Model) -> Task {
    let crowd = sinmdm::run(
        model,
        &request(model, Task::Generate { frames: 60 }, 1),
        &mut go(),
    )
    .unwrap();
    Task::Inbetween {
        reference: crowd.features.slice(s![0, .., ..]).to_owned(),
        keep: vec![Span::new(0, 15), Span::new(45, 60)],
        ramp: 4,
    }
}

#[test]
fn stepping_a_run_any_number_of_steps_at_a_time_gives_the_one_call_bits() {
    let mut model = model_with(2);
    for task in [Task::Generate { frames: 50 }, inbetween(&mut model)] {
        let req = request(&model, task, 2);
        let once = sinmdm::run(&mut model, &req, &mut go()).unwrap();
        for per_call in [1, 3, usize::MAX] {
            let mut run = sinmdm::plan(model.metadata(), &req)
                .unwrap()
                .start()
                .unwrap();
            let mut calls = 0;
            while !run.progress().is_finished() {
                let progress = run.step(&mut model, per_call).unwrap();
                calls += 1;
                assert!(progress.done <= progress.total && progress.total == 9);
            }
            assert_eq!(calls, 9usize.div_ceil(per_call.min(9)));
            let stepped = run.finish().unwrap();
            assert_eq!(
                stepped.normalized, once.normalized,
                "{per_call} steps a call"
            );
            assert_eq!(stepped.poses(1).unwrap(), once.poses(1).unwrap());
        }
    }
}

#[test]
fn a_cancelled_run_can_go_on_or_finish_early() {
    let mut model = model_with(1);
    let req = request(&model, Task::Generate { frames: 40 }, 1);
    let once = sinmdm::run(&mut model, &req, &mut go()).unwrap();
    let plan = sinmdm::plan(model.metadata(), &req).unwrap();

    let mut run = plan.start().unwrap();
    let mut cancel_at_4 = |done: usize, _: usize| {
        if done == 4 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    };
    let stopped = run.complete(&mut model, &mut cancel_at_4);
    assert!(
        matches!(stopped, Err(TaskError::Cancelled { done: 4, steps: 9 })),
        "{stopped:?}"
    );
    run.complete(&mut model, &mut go()).unwrap();
    assert_eq!(run.finish().unwrap().normalized, once.normalized);

    // Finished early: the network's latest guess at the clean motion, decodable into poses.
    let mut early = plan.start().unwrap();
    early.step(&mut model, 5).unwrap();
    let preview = early.finish().unwrap();
    assert_eq!(preview.normalized.dim(), once.normalized.dim());
    assert_ne!(preview.normalized, once.normalized);
    assert_eq!(preview.poses(0).unwrap().len(), 40);

    let unstarted = plan.start().unwrap().finish();
    assert!(
        matches!(unstarted, Err(TaskError::NotStarted { steps: 9 })),
        "{unstarted:?}"
    );
}

#[test]
fn a_run_is_owned_and_can_move_to_another_thread() {
    fn owned<T: Send + 'static>(_: &T) {}
    let mut model = model_with(1);
    let req = request(&model, Task::Generate { frames: 30 }, 1);
    let run = sinmdm::plan(model.metadata(), &req)
        .unwrap()
        .start()
        .unwrap();
    owned(&run);
    let moved: Run = std::thread::spawn(move || run).join().unwrap();
    let mut moved = moved;
    moved.step(&mut model, usize::MAX).unwrap();
    let once = sinmdm::run(&mut model, &req, &mut go()).unwrap();
    assert_eq!(moved.finish().unwrap().normalized, once.normalized);
}

fn stream_options() -> StreamOptions {
    StreamOptions {
        seed: 5,
        steps: Some(4),
        block_frames: Some(40),
        ..StreamOptions::default()
    }
}

#[test]
fn a_stream_prepared_ahead_reads_without_waiting_and_gives_the_blocking_bits() {
    let mut model = model_with(1);
    let mut blocking = Stream::new(model.metadata(), stream_options()).unwrap();
    let want: Vec<_> = [25, 30, 50]
        .iter()
        .map(|&n| blocking.next(&mut model, n).unwrap())
        .collect();

    let mut stepped = Stream::new(model.metadata(), stream_options()).unwrap();
    for (i, &n) in [25usize, 30, 50].iter().enumerate() {
        // A frame's budget of one step at a time until the chunk is ready.
        let mut frames_of_game = 0;
        while stepped.ready_frames() < n {
            let mut counting = Counting {
                model: &mut model,
                calls: 0,
            };
            let progress = stepped.prepare(&mut counting, 1, n).unwrap();
            assert!(counting.calls <= 1, "one step at most per prepare");
            assert!(progress.done <= progress.total);
            frames_of_game += 1;
            assert!(frames_of_game < 100);
        }
        let mut counting = Counting {
            model: &mut model,
            calls: 0,
        };
        let chunk = stepped.next(&mut counting, n).unwrap();
        assert_eq!(
            counting.calls, 0,
            "next() ran the network although frames were ready"
        );
        assert_eq!(chunk, want[i], "chunk {i}");
    }
    // A block half made by prepare is finished by next() without changing its bits.
    let mut half = Stream::new(model.metadata(), stream_options()).unwrap();
    half.prepare(&mut model, 2, 1).unwrap();
    assert_eq!(half.block_progress().done, 2);
    assert_eq!(half.next(&mut model, 25).unwrap(), want[0]);
}

#[test]
fn thread_count_and_batch_position_do_not_change_a_samples_bits() {
    let req = |count| Request {
        task: Task::Generate { frames: 120 },
        count,
        seed: 8,
        steps: Some(6),
        feet: Feet::Planted,
        method: Default::default(),
    };
    let mut one = model_with(1);
    let alone = sinmdm::run(&mut one, &req(1), &mut go()).unwrap();
    let crowd_one_thread = sinmdm::run(&mut one, &req(3), &mut go()).unwrap();
    for threads in [2, 4] {
        let mut model = model_with(threads);
        let crowd = sinmdm::run(&mut model, &req(3), &mut go()).unwrap();
        for sample in 0..3 {
            assert_eq!(
                crowd.poses(sample).unwrap(),
                crowd_one_thread.poses(sample).unwrap(),
                "{threads} threads, sample {sample}"
            );
        }
        let single = sinmdm::run(&mut model, &req(1), &mut go()).unwrap();
        assert_eq!(single.poses(0).unwrap(), alone.poses(0).unwrap());
    }
    // Sample 0 of a batch is the same seed alone (its noise is the batch's first rows).
    assert_eq!(
        crowd_one_thread.normalized.slice(s![0..1, .., ..]),
        alone.normalized.view()
    );
}

#[test]
fn threads_past_the_limit_are_refused_when_the_model_opens() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../onnx-models/human_walk_cmu.onnx");
    let e = Model::open(
        path,
        &ModelOptions {
            threads: Some(sinmdm::limits::MAX_THREADS + 1),
        },
    )
    .unwrap_err();
    assert!(
        matches!(e, ModelError::Threads(n) if n == sinmdm::limits::MAX_THREADS + 1),
        "{e}"
    );
}

/// The model writes each step's prediction into a reused buffer (`denoise_into`); a denoiser
/// that only allocates (`denoise`, the trait's default for `denoise_into`) gives the same bits,
/// and a buffer of another shape is reshaped, not misread.
#[test]
fn predictions_written_in_place_equal_allocated_ones() {
    let mut model = model_with(2);
    let task = Task::Generate { frames: 64 };
    let asked = request(&model, task, 3);
    let in_place = sinmdm::run(&mut model, &asked, &mut go()).unwrap();
    let plan = sinmdm::plan(model.metadata(), &asked).unwrap();
    let mut counting = Counting {
        model: &mut model,
        calls: 0,
    };
    let allocated = plan.run(&mut counting, &mut go()).unwrap();
    assert_eq!(counting.calls, 9);
    assert_eq!(in_place.normalized, allocated.normalized);

    let f = model.features();
    let x = Array3::from_shape_fn((3, f, 40), |(b, r, c)| {
        ((b * 7 + r * 3 + c) % 11) as f32 / 5.0
    });
    let t = [999, 500, 3];
    let fresh = model.denoise(x.view(), &t).unwrap();
    let mut reused = Array3::from_elem((1, 2, 3), f32::NAN);
    model.denoise_into(x.view(), &t, &mut reused).unwrap();
    assert_eq!(reused, fresh);
    // The same buffer again, now of the right shape, for other inputs.
    let y = x.mapv(|v| -v);
    model.denoise_into(y.view(), &t, &mut reused).unwrap();
    assert_eq!(reused, model.denoise(y.view(), &t).unwrap());
    assert_ne!(reused, fresh);
}
