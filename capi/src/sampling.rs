//! The sampling settings every task shares, and their C constants.

use sinmdm::{Feet, Request, Task};

use crate::status::Failure;

/// Respaced sampling steps of the command line (the library's `DEFAULT_STEPS`); what a `steps`
/// of 0 gives in `SinmdmSampling` (a stream's is `SINMDM_DEFAULT_STREAM_STEPS`).
pub const SINMDM_DEFAULT_STEPS: u32 = 50;

/// Respaced sampling steps per block of a stream (the library's `DEFAULT_STREAM_STEPS`); what a
/// `steps` of 0 gives in `SinmdmStreamOptions`.
pub const SINMDM_DEFAULT_STREAM_STEPS: u32 = 20;

/// A `steps` value that runs all of the model's diffusion steps T (slow; the reference quality).
pub const SINMDM_ALL_STEPS: u32 = u32::MAX;

/// The library's step count for a C `steps` value: 0 is the default, `SINMDM_ALL_STEPS` all T.
pub(crate) fn steps_arg(steps: u32) -> Option<usize> {
    steps_or(steps, sinmdm::DEFAULT_STEPS)
}

/// As [`steps_arg`], with `default` for 0 (a stream's is `SINMDM_DEFAULT_STREAM_STEPS`).
pub(crate) fn steps_or(steps: u32, default: usize) -> Option<usize> {
    match steps {
        0 => Some(default),
        SINMDM_ALL_STEPS => None,
        n => Some(n as usize),
    }
}

/// A request of `task` with the C sampling settings, each checked.
pub(crate) fn request(sampling: &SinmdmSampling, task: Task) -> Result<Request, Failure> {
    Ok(Request {
        task,
        count: sampling.count as usize,
        seed: sampling.seed,
        steps: steps_arg(sampling.steps),
        feet: feet_arg(sampling.feet)?,
        method: method_arg(sampling.method, sampling.eta)?,
    })
}

/// Feet: contact points held still on the ground (the default).
pub const SINMDM_FEET_PLANTED: u32 = 0;
/// Feet: the network's motion untouched.
pub const SINMDM_FEET_RAW: u32 = 1;

/// Sampling method: ancestral DDPM (the paper's sampler; the default).
pub const SINMDM_METHOD_ANCESTRAL: u32 = 0;
/// Sampling method: DDIM, with `eta` the share of the ancestral noise (0: deterministic).
pub const SINMDM_METHOD_DDIM: u32 = 1;
/// Sampling method: DPM-Solver++(2M), deterministic, good motion in fewer steps.
pub const SINMDM_METHOD_DPM2M: u32 = 2;

/// A `method` and `eta` as the library's setting.
pub(crate) fn method_arg(method: u32, eta: f64) -> Result<sinmdm::Method, Failure> {
    let chosen = match method {
        SINMDM_METHOD_ANCESTRAL => sinmdm::Method::Ancestral,
        SINMDM_METHOD_DDIM => sinmdm::Method::Ddim { eta },
        SINMDM_METHOD_DPM2M => sinmdm::Method::DpmSolver2M,
        other => {
            return Err(Failure::invalid(format!(
                "method must be SINMDM_METHOD_ANCESTRAL (0), SINMDM_METHOD_DDIM (1) or SINMDM_METHOD_DPM2M (2), got {other}"
            )));
        }
    };
    if let Some(problem) = chosen.problem() {
        return Err(Failure::invalid(problem));
    }
    Ok(chosen)
}

/// A `feet` field's value as the library's setting.
pub(crate) fn feet_arg(feet: u32) -> Result<Feet, Failure> {
    match feet {
        SINMDM_FEET_PLANTED => Ok(Feet::Planted),
        SINMDM_FEET_RAW => Ok(Feet::Raw),
        other => Err(Failure::invalid(format!(
            "feet must be SINMDM_FEET_PLANTED (0) or SINMDM_FEET_RAW (1), got {other}"
        ))),
    }
}

/// Sampling settings shared by every task. The same model, settings and arguments give the same
/// poses, here, in Rust and in the Python reference.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmSampling {
    /// Seed of the portable noise.
    pub seed: u64,
    /// Samples in the batch (a crowd when more than 1).
    pub count: u32,
    /// Respaced denoising steps; 0 for `SINMDM_DEFAULT_STEPS`, `SINMDM_ALL_STEPS` for all of
    /// the model's T.
    pub steps: u32,
    /// `SINMDM_FEET_PLANTED` or `SINMDM_FEET_RAW`.
    pub feet: u32,
    /// `SINMDM_METHOD_ANCESTRAL` (0, the default), `SINMDM_METHOD_DDIM` or `SINMDM_METHOD_DPM2M`.
    pub method: u32,
    /// DDIM's share of the ancestral noise, 0 to 1 (ignored by the other methods).
    pub eta: f64,
}

/// A span of frames `start..end` (end excluded).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmSpan {
    /// First frame.
    pub start: usize,
    /// One past the last frame.
    pub end: usize,
}

#[cfg(test)]
mod default_steps_tests {
    use super::*;

    #[test]
    fn the_c_default_is_the_library_default() {
        assert_eq!(SINMDM_DEFAULT_STEPS as usize, sinmdm::DEFAULT_STEPS);
        assert_eq!(steps_arg(0), Some(sinmdm::DEFAULT_STEPS));
        assert_eq!(steps_arg(SINMDM_DEFAULT_STEPS), Some(sinmdm::DEFAULT_STEPS));
        assert_eq!(
            SINMDM_DEFAULT_STREAM_STEPS as usize,
            sinmdm::DEFAULT_STREAM_STEPS
        );
        assert_eq!(
            steps_or(0, sinmdm::DEFAULT_STREAM_STEPS),
            Some(sinmdm::DEFAULT_STREAM_STEPS)
        );
        assert_eq!(steps_arg(SINMDM_ALL_STEPS), None);
        assert_eq!(steps_arg(7), Some(7));
    }
}
