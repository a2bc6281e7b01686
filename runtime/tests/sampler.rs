//! The sampler as a stepper, tasks over any denoiser, and cancelling a run: through the real
//! model where a network is needed, through small denoisers with known answers otherwise.

mod common;

use std::convert::Infallible;
use std::ops::ControlFlow;

use ndarray::{Array2, Array3, ArrayView3};
use sinmdm::diffusion::{Guidance, Inpainting, Sampler, Schedule};
use sinmdm::{Denoiser, Model, Request, Task, TaskError};

fn model() -> Model {
    common::tiny_model()
}

fn request(task: Task, count: usize) -> Request {
    Request {
        task,
        count,
        seed: 11,
        steps: Some(12),
        feet: sinmdm::Feet::default(),
        method: Default::default(),
    }
}

#[test]
fn stepping_by_hand_gives_exactly_what_the_whole_loop_gives() {
    let mut m = model();
    let plan = sinmdm::plan(m.metadata(), &request(Task::Generate { frames: 40 }, 2)).unwrap();
    let whole = plan
        .run(&mut m, &mut |_, _| ControlFlow::Continue(()))
        .unwrap()
        .normalized;
    let mut sampler = plan.sampler().unwrap();
    let mut seen = Vec::new();
    while !sampler.is_finished() {
        sampler.step(&mut m).unwrap();
        seen.push(sampler.done());
    }
    assert_eq!(seen, (1..=12).collect::<Vec<_>>());
    // A finished sampler does nothing more.
    sampler.step(&mut m).unwrap();
    assert_eq!(sampler.into_sample(), whole);
}

#[test]
fn the_progress_callback_cancels_a_run() {
    let mut m = model();
    let plan = sinmdm::plan(m.metadata(), &request(Task::Generate { frames: 30 }, 1)).unwrap();
    let mut calls = 0;
    let e = plan
        .run(&mut m, &mut |done, steps| {
            calls += 1;
            assert_eq!(steps, 12);
            if done == 3 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .unwrap_err();
    assert_eq!(calls, 3, "no step runs after the callback says stop");
    assert!(
        matches!(e, TaskError::Cancelled { done: 3, steps: 12 }),
        "{e:?}"
    );
}

/// A denoiser that predicts garbage: a function of the input that is nothing like motion.
struct Garbage {
    features: usize,
}

impl Denoiser for Garbage {
    type Error = Infallible;
    fn features(&self) -> usize {
        self.features
    }
    fn denoise(&mut self, x_t: ArrayView3<'_, f32>, t: &[i64]) -> Result<Array3<f32>, Infallible> {
        Ok(x_t.mapv(|v| 3.0 * v.sin() + t[0] as f32 * 1e-3))
    }
}

#[test]
fn a_task_runs_on_any_denoiser_and_a_full_mask_returns_the_reference() {
    // With the mask 1 everywhere every prediction is the reference, and the last step of the
    // posterior keeps only the prediction (coefficients 1 and 0), whatever the network says.
    let m = model();
    let f = m.features();
    let reference =
        Array2::from_shape_fn((f, 25), |(r, n)| (r as f32 * 0.1 - n as f32 * 0.05).sin());
    let normalized = m.metadata().normalizer.normalize(reference.view());
    let schedule = Schedule::respaced(m.metadata().diffusion.steps, 8).unwrap();
    let guidance = Guidance {
        inpainting: Some(Inpainting {
            reference: normalized.clone(),
            mask: Array2::ones((f, 25)),
        }),
        harmonization: None,
        steering: None,
    };
    let mut sampler = Sampler::new(&schedule, &guidance, 3, f, 25, 5).unwrap();
    while !sampler.is_finished() {
        sampler.step(&mut Garbage { features: f }).unwrap();
    }
    let out = sampler.into_sample();
    for s in out.outer_iter() {
        let worst = (&s - &normalized)
            .mapv(f32::abs)
            .fold(0f32, |a, &b| a.max(b));
        assert!(worst < 1e-6, "max |diff| {worst}");
    }
    // The same through a checked plan: an in-between keeping every frame.
    let plan = sinmdm::plan(
        m.metadata(),
        &request(
            Task::Inbetween {
                reference: reference.clone(),
                keep: vec![sinmdm::Span::new(0, 25)],
                ramp: 0,
            },
            2,
        ),
    )
    .unwrap();
    let generated = plan
        .run(&mut Garbage { features: f }, &mut |_, _| {
            ControlFlow::Continue(())
        })
        .unwrap();
    for s in generated.features.outer_iter() {
        let worst = (&s - &reference)
            .mapv(f32::abs)
            .fold(0f32, |a, &b| a.max(b));
        assert!(worst < 1e-4, "max |diff| {worst}");
    }
}

#[test]
fn a_sampler_refuses_guidance_of_the_wrong_shape() {
    let schedule = Schedule::respaced(1000, 4).unwrap();
    let guidance = Guidance {
        inpainting: Some(Inpainting {
            reference: Array2::zeros((5, 10)),
            mask: Array2::zeros((5, 9)),
        }),
        harmonization: None,
        steering: None,
    };
    let e = sinmdm::Sampler::new(&schedule, &guidance, 1, 5, 10, 0).unwrap_err();
    assert!(e.to_string().contains("inpainting mask"), "{e}");
    let e = sinmdm::Sampler::new(&schedule, &Guidance::default(), 0, 5, 10, 0).unwrap_err();
    assert!(
        matches!(e, sinmdm::SamplerError::Empty { batch: 0, .. }),
        "{e:?}"
    );
    let mut wrong = Garbage { features: 4 };
    let plain = Guidance::default();
    let mut sampler = sinmdm::Sampler::new(&schedule, &plain, 1, 5, 10, 0).unwrap();
    assert!(sampler.step(&mut wrong).is_err());
    assert_eq!(sampler.done(), 0);
}

#[test]
fn a_step_split_around_the_network_call_is_the_same_bits_and_can_be_given_up() {
    let mut m = model();
    let plan = sinmdm::plan(m.metadata(), &request(Task::Generate { frames: 40 }, 2)).unwrap();
    let mut whole = plan.sampler().unwrap();
    while !whole.is_finished() {
        whole.step(&mut m).unwrap();
    }
    let mut split = plan.sampler().unwrap();
    assert!(matches!(
        split.finish_step(whole.current()),
        Err(sinmdm::diffusion::SamplerError::StepNotBegun)
    ));
    let mut given_up = 0;
    while let Some(t) = split.begin_step() {
        // Beginning twice asks for nothing more.
        assert_eq!(split.begin_step(), Some(t));
        if split.done() % 5 == 2 && given_up < split.done() {
            // The network "failed": the step is given up and begun again.
            split.abandon_step();
            given_up = split.done();
            continue;
        }
        let rows = split.current().dim().0;
        let x0 = m.denoise(split.current(), &vec![t; rows]).unwrap();
        split.finish_step(x0.view()).unwrap();
    }
    assert!(given_up > 0);
    let bits = |s: Sampler| {
        s.into_sample()
            .iter()
            .map(|v| v.to_bits())
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(split), bits(whole));
}
